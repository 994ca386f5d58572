"""``hertzchain compare`` in the sonic vacuum runs the better continuum by default.

``[models] continuum`` not given in ``compare`` is ``"auto"``, resolved by the one rule
:meth:`hertzchain.scenario.ModelsSpec.continuum_model`: at δ0 = 0 on a lossless chain the
grain-averaged quasi-continuum (docs/physics.md §24), not Eq. 7.  The scenario is the
model-validity map's sonic-vacuum point at the interface (α_ρ, α_kn) = (2, 1/2) (its
``--quick`` row: chain, exact incident wave and run length from
:func:`hertzchain.reproduce.validity.amplitude_row`), run through the CLI three times: as a
user gets it, with ``--continuum eq7``, and with the quasi-continuum stepped at Eq. 4's and
Eq. 7's own step (Yoshida-4 drift first at ``dt_safety`` 0.5, the scenario-wide default
before each model declared its own).
"""

import json
import math

from hertzchain.cli import main
from hertzchain.reproduce.validity import amplitude_row
from hertzchain.scenario import load_scenario

QC_BOUND = 0.02
"""The quasi-continuum's error (largest of |ΔE_T|, |ΔE_R| over the incident energy and the
relative transmitted front speed) is within 2.2 % on every compared point of the map's
strongly nonlinear rows; on this point it is 0.15 % at its own step, position Verlet at
dt_safety 0.8, and 0.51 % at Yoshida-4 and 0.5 (Eq. 7: 3.5 %)."""
RATIO = 0.5
"""The quasi-continuum's error is below half Eq. 7's on this point (measured ratio 1/23):
a rule that ran Eq. 7, or a quasi-continuum as poor as Eq. 7, fails."""


def _compare(tmp_path, capsys, toml, *extra) -> dict:
    out = tmp_path / ("cmp" + "-".join(extra))
    assert main(["compare", str(toml), "--out", str(out), "--json", "--no-progress",
                 *extra]) == 0
    return json.loads(capsys.readouterr().out)


def test_sonic_vacuum_compare_runs_the_quasi_continuum_closer_than_eq7(tmp_path, capsys):
    row = amplitude_row(math.inf, 0.0)
    toml = tmp_path / "sonic.toml"
    toml.write_text(f"""name = "sonic-vacuum-interface"
[chain]
delta0_over_d = 0.0
[[chain.sections]]
n = {row['n_left']}
[[chain.sections]]
n = {row['n_right']}
alpha_rho = 2.0
alpha_kn = 0.5
[initial]
kind = "exact_wave"
center = {row['center']}
strain_max = {row['strain_max']!r}
[run]
t_end = {row['t_end']!r}
[models]
samples = 60
""", encoding="utf-8")
    auto = _compare(tmp_path, capsys, toml)
    eq7 = _compare(tmp_path, capsys, toml, "--continuum", "eq7")["summary"]
    # the same quasi-continuum at Yoshida-4 and dt_safety 0.5 (given explicitly)
    y4 = tmp_path / "sonic-yoshida4.toml"
    y4.write_text(toml.read_text(encoding="utf-8").replace(
        "[models]\n", "[models]\ncontinuum = \"qc\"\nintegrator = \"position_yoshida4\"\n"
        "dt_safety = 0.5\n"), encoding="utf-8")
    slow = _compare(tmp_path, capsys, y4)
    auto, slow = auto["summary"], slow["summary"]
    # auto runs the quasi-continuum at its own step, position Verlet at 0.8 (the run
    # resolves it by the same ModelsSpec.continuum_step); an identical run at Yoshida-4
    # and 0.5 would give the same error and fail the strict comparison below
    models = load_scenario(toml).with_default_models(compare=True).models
    assert models.continuum_step(auto["continuum_model"]) == ("position_verlet", 0.8)
    assert load_scenario(y4).models.continuum_step("qc") == ("position_yoshida4", 0.5)
    assert auto["continuum_model"] == "qc" and eq7["continuum_model"] == "eq7"
    qc_err, eq7_err = auto["continuum_error"], eq7["continuum_error"]
    assert qc_err is not None and eq7_err is not None, (auto, eq7)  # both compared
    assert qc_err < QC_BOUND and qc_err < RATIO * eq7_err, (qc_err, eq7_err)
    # its own step is the closer to the chain here (measured 0.15 % against 0.51 % of
    # the incident energy: a gap far above round-off, so the strict order is the test)
    # and the cheaper one (one force evaluation per step against three, at 1.6× the step)
    assert qc_err < slow["continuum_error"] < QC_BOUND, (qc_err, slow["continuum_error"])
