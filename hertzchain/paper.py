"""The paper's reported numbers and set-ups, in one place.

Reference: "Asymmetric scattering effect of solitary wave in a two-section composite
granular chain".  Every value carries the place it is printed.
"""

from __future__ import annotations

from types import MappingProxyType

__all__ = ["VMAX_OVER_V0", "TABLE2", "TABLE2_KEYS", "FIG_SETUPS", "DIAMETER", "V0"]

DIAMETER = 5e-3
"""Grain diameter d, m (Table 1)."""

V0 = 1.0
"""Impact velocity of the left-most grain, m/s (Section 2)."""

VMAX_OVER_V0 = MappingProxyType({0.0: 0.6816, 1e-3: 0.0822})
"""Mean per-grain maximum velocity of the formed solitary wave / v0, keyed by δ0/d
(Section 2, Fig. 2)."""

TABLE2_KEYS = ("Ek_tr", "Ek_re", "Ep_tr", "Ep_re", "Et_tr", "Et_re")

_ROWS = {
    "M": (0.88806, 0.11067, 1.31701, -0.31695, 1.29891, -0.29891),
    "N": (0.88971, 0.11089, 0.67482, 0.32516, 0.68388, 0.31612),
    "P": (0.99975, 0.00023, 0.99996, 0.00004, 0.99996, 0.00004),
    "Q": (0.99997, 0.00001, 0.99997, 0.00003, 0.99997, 0.00003),
}
TABLE2 = MappingProxyType(
    {point: dict(zip(TABLE2_KEYS, row, strict=True)) for point, row in _ROWS.items()}
)
"""Table 2: transmitted and reflected kinetic, potential and total energy over the
incident ones, δ0^L/d = 1e-3, interface between grains 200 and 201."""

FIG_SETUPS = MappingProxyType({
    # figure: (delta0/d of the left section, grains left of the interface, snapshot grain)
    "fig3": {"delta0_over_d": 0.0, "interface": 400, "snapshot_grain": 550,
             "alpha_rho": (0.2, 5.0), "alpha_kn": (1.0, 1.0),
             "time_series_grains": tuple(range(395, 403))},
    "fig4": {"delta0_over_d": 0.0, "interface": 200, "snapshot_grain": None,
             "alpha_rho": (1.0, 1.0), "alpha_kn": (0.2, 5.0),
             "time_series_grains": tuple(range(195, 203))},
    "fig5": {"delta0_over_d": 1e-3, "interface": 35000, "n_grains": 50000,
             "snapshot_grain": 49900},
    "fig8": {"delta0_over_d": 1e-3, "interface": 200},
})
"""Set-ups as printed in Section 4 (grain numbers are the paper's, 1-based)."""
