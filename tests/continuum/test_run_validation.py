"""continuum.run: bad input is a ValueError naming the parameter and its range; an unstable
integration is an InstabilityError naming the cause and the stable step (issue: no silent
wrong result).  Each case returned garbage, looped or crashed before."""

import math

import numpy as np
import pytest

import theory
from continuum import (
    BoussinesqPDE,
    InstabilityError,
    KdVPDE,
    Medium,
    NesterenkoPDE,
    compacton,
    compacton_parameters,
    from_grains,
    run,
    solitary_wave,
)

D = theory.PAPER_DIAMETER
DELTA0 = 1e-3 * D


@pytest.fixture(scope="module")
def wave():
    pde = BoussinesqPDE(Medium.uniform(120, DELTA0), 3)
    state = solitary_wave(pde, 40.0, velocity_max=0.0822)
    return pde, state


@pytest.mark.parametrize(("kwargs", "name"), [
    ({"dt": float("nan")}, "dt"),
    ({"dt": 0.0}, "dt"),                  # was ZeroDivisionError
    ({"dt": -1e-7}, "dt"),                # looped forever
    ({"dt": float("inf")}, "dt"),
    ({"dt": "abc"}, "dt"),
    ({"t_end": float("nan")}, "t_end"),   # returned the initial state
    ({"t_end": -1e-4}, "t_end"),          # returned the initial state
    ({"t_end": float("inf")}, "t_end"),
    ({"interval": 0.0}, "interval"),
    ({"interval": float("nan")}, "interval"),
    ({"order": 3}, "order"),
    ({"method": "rk4"}, "method"),
    ({"method": "blanes_moan4", "order": 2}, "order"),
    ({"backend": "cuda"}, "backend"),
    ({"drift_tolerance": 0.0}, "drift_tolerance"),
    ({"dt": 1e-300}, "dt"),               # 1e296 steps: would run forever
])
def test_bad_input_names_the_parameter(wave, kwargs, name):
    pde, state = wave
    args = {"t_end": 1e-4, **kwargs}
    t_end = args.pop("t_end")
    with pytest.raises(ValueError, match=rf"^{name} ") as exc:
        run(pde, state, t_end, **args)
    assert "must be" in str(exc.value)  # the allowed range is stated


def test_non_finite_initial_state_is_rejected(wave):
    pde, state = wave
    bad = state.copy()
    bad[1].data[10] = np.nan
    with pytest.raises(ValueError, match="state must be finite"):
        run(pde, bad, 1e-5)


def test_zero_duration_returns_the_initial_state(wave):
    """t_end = 0 is valid: no step, the initial state and one monitor record."""
    pde, state = wave
    res = run(pde, state, 0.0)
    np.testing.assert_array_equal(res["state"].data, state.data)
    assert res["times"].tolist() == [0.0]


@pytest.mark.parametrize("factor", [3.0, 50.0])
def test_too_large_dt_raises_instability(wave, factor):
    """dt = 3× and 50× the stable step (NaN state with only a RuntimeWarning, resp. an
    energy drift of 8.7e13, before): InstabilityError naming the cause, dt and the
    stable step; never a NaN result."""
    pde, state = wave
    stable = pde.stable_dt(state)
    with pytest.raises(InstabilityError) as exc:
        run(pde, state, 200 * factor * stable, dt=factor * stable)
    msg = str(exc.value)
    assert "non-finite state" in msg or "drift" in msg
    assert f"{stable:.4g} s for the initial state" in msg
    assert f"dt = {factor * stable:.4g} s" in msg


def test_large_amplitude_names_the_ill_posed_flux():
    """A velocity impulse of 5 m/s on five grains of a precompressed chain stretches the
    contacts beyond -2 δ0, where Eq. 4's quadratic flux loses stiffness: the run blew up
    to NaN silently before; now the error says why."""
    pde = BoussinesqPDE(Medium.uniform(200, DELTA0), 5)
    vg = np.zeros(200)
    vg[100:105] = 5.0
    state = from_grains(pde, np.zeros(200), vg)
    with pytest.raises(InstabilityError, match="amplitude: the strain reached"):
        run(pde, state, 2e-4, interval=2e-5)


def test_nesterenko_too_large_dt_raises():
    med = Medium.uniform(60, 0.0)
    amp = compacton_parameters(NesterenkoPDE(med, 1, delta_floor=0.0), velocity_max=0.68)
    pde = NesterenkoPDE(med, 3, delta_floor=1e-2 * amp["amplitude"])
    state = compacton(pde, 15.0, velocity_max=0.68)
    stable = pde.stable_dt(state)
    with pytest.raises(InstabilityError, match="stable step"):
        run(pde, state, 3000 * stable, dt=30 * stable)


def test_kdv_too_large_dt_raises():
    pde = KdVPDE.for_medium(Medium.uniform(5, DELTA0))
    grid = KdVPDE.grid(60, 3)
    s0 = pde.soliton(grid, 0.09 * DELTA0, 20.0)
    stable = pde.stable_dt(s0)
    with pytest.raises(InstabilityError, match="KdVPDE"):
        run(pde, s0, 2000 * stable, dt=10 * stable)


def test_results_are_finite_or_raise(wave):
    """The stable default path returns finite numbers and a small drift."""
    pde, state = wave
    res = run(pde, state, 2e-4)
    assert np.all(np.isfinite(res["state"].data))
    assert math.isfinite(res.energy_drift) and res.energy_drift < 1e-4
