"""The continuum models registry: a new model is one class and one register_model call."""

import numpy as np
import pytest

import continuum
import theory
from continuum import MODELS, BoussinesqPDE, ChainPDEBase, register_model, run, solitary_wave

D = theory.PAPER_DIAMETER


class LinearLongWaves(BoussinesqPDE):
    """A model defined here: the linearised Eq. 4 (acoustics), for the registry test."""

    name = "test-linear"
    label = "linear Eq. 4"

    @classmethod
    def for_chain(cls, medium, *, nodes_per_grain, bc, options):
        return cls(medium, nodes_per_grain, bc=bc, nonlinearity="linear")


def test_paper_models_are_registered():
    assert MODELS["eq4"] is continuum.BoussinesqPDE
    assert MODELS["eq7"] is continuum.NesterenkoPDE
    assert MODELS["eq4"].label == "Eq. 4" and MODELS["eq7"].label == "Eq. 7"


def test_a_model_defined_in_a_test_module_registers_and_runs():
    """Registered under its name, found by the scenario runner's constructor path
    (hertzchain.models' ``_pde``), run like the others: a small wave keeps its energy
    (the symplectic stepper: drift < 1e-6)."""
    register_model(LinearLongWaves)
    try:
        assert MODELS["test-linear"] is LinearLongWaves
        med = continuum.Medium.uniform(120, 1e-3 * D)
        from hertzchain.models import IncidentWave, _pde
        from hertzchain.scenario import ModelsSpec

        pde = _pde("test-linear", med, ModelsSpec(continuum="auto"), "free",
                   IncidentWave(20.0, 1e-3, 1e-5, 0.0), D)
        assert isinstance(pde, LinearLongWaves) and pde.nonlinearity == "linear"
        state = solitary_wave(pde, 50.0, velocity_max=0.02)
        res = run(pde, state, 1e-4, order=4)
        assert res.energy_drift < 1e-6
        assert np.all(np.isfinite(res["state"].data))
    finally:
        MODELS.pop("test-linear", None)


def test_bad_registrations_are_refused():
    with pytest.raises(ValueError, match="subclass"):
        register_model(int)

    class NoName(BoussinesqPDE):
        name = ""

    with pytest.raises(ValueError, match="name must be a non-empty string"):
        register_model(NoName)

    class NoConstructor(ChainPDEBase):
        name, label = "test-none", "none"

    with pytest.raises(ValueError, match="for_chain"):
        register_model(NoConstructor)

    class Thief(BoussinesqPDE):
        name, label = "eq4", "another Eq. 4"

    with pytest.raises(ValueError, match="taken"):
        register_model(Thief)
    assert MODELS["eq4"] is BoussinesqPDE


def test_a_model_declares_a_stable_default_step():
    """A model's own step (``default_integrator``, ``default_dt_safety``: what a scenario
    that gives neither runs) must name a splitting method and lie inside half its
    stability limit (ω_max Δt = 2 safety < limit); register_model refuses it otherwise."""
    from theory.splitting import SPLITTINGS, STABILITY_LIMITS

    for cls in MODELS.values():
        assert cls.default_integrator in SPLITTINGS
        assert 0 < 2 * cls.default_dt_safety < STABILITY_LIMITS[cls.default_integrator]

    class NoStep(ChainPDEBase):
        name, label = "test-nostep", "no step"

        @classmethod
        def for_chain(cls, medium, *, nodes_per_grain, bc, options):
            return cls(medium, nodes_per_grain, bc=bc)

    with pytest.raises(ValueError, match=r"NoStep.default_integrator must name a splitting"):
        register_model(NoStep)

    class RungeKutta(LinearLongWaves):
        name, default_integrator = "test-rk4", "rk4"

    with pytest.raises(ValueError, match=r"default_integrator must name .* \(got 'rk4'\)"):
        register_model(RungeKutta)

    class TooLong(LinearLongWaves):  # qc's 0.8 is beyond Yoshida-4's (0, 0.7865)
        name, default_dt_safety = "test-long", 0.8

    with pytest.raises(ValueError, match=r"TooLong.default_dt_safety must lie in \(0, 0.7865\)"):
        register_model(TooLong)
    assert not {"test-nostep", "test-rk4", "test-long"} & set(MODELS)
