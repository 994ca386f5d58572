"""The names ``theory`` exports from its chain modules (gravity, tapers, dimers,
dissipation, striker): loaded on first use, each the module's own object, none clashing."""

import importlib
import subprocess
import sys

import pytest

import theory

CHAIN_MODULES = ("gravity", "tapers", "dimers", "dissipation", "striker")
MODULE_ONLY = {"gravity": {"solitary_wave_energy", "solitary_wave_amplitude"}}
"""Generic names used as theory.<module>.<name> only (theory/__init__'s docstring)."""


@pytest.mark.parametrize("module", CHAIN_MODULES)
def test_every_public_name_is_exported_or_module_only(module):
    # Every name of the module's __all__ is theory.<name> (the same object, listed in
    # theory.__all__) or, if generic, reachable through the module only: a name added to
    # a module without its export fails here.
    mod = importlib.import_module(f"theory.{module}")
    assert getattr(theory, module) is mod
    only = MODULE_ONLY.get(module, set())
    assert only <= set(mod.__all__)
    for name in mod.__all__:
        if name in only:
            assert not hasattr(theory, name) and name not in theory.__all__
        else:
            assert getattr(theory, name) is getattr(mod, name), name
            assert name in theory.__all__ and name in dir(theory)


def test_no_clash_and_unknown_names_raise():
    # theory.__all__ has no duplicate (an exported chain name shadowing an eager one would
    # appear twice), and an unknown name is an AttributeError naming it.
    assert len(theory.__all__) == len(set(theory.__all__))
    with pytest.raises(AttributeError, match="no_such_name"):
        theory.no_such_name  # noqa: B018


def test_import_theory_loads_no_chain_module():
    # `import theory` stays free of the chain modules and of SciPy (they import it: the
    # start-up of `hertzchain run`); the first use of an exported name loads its module.
    code = ("import sys, theory\n"
            "mods = [m for m in ('theory.gravity', 'theory.tapers', 'theory.dimers',"
            " 'theory.dissipation', 'theory.striker', 'scipy') if m in sys.modules]\n"
            "t = theory.striker_train(4.0)\n"
            "print(mods, 'theory.striker' in sys.modules, t.mass_ratio)")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["[]", "True", "4.0"]
