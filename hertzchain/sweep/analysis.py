r"""Agreement of the measured classification with the theory regions of the paper's Fig. 7.

The linear-acoustic theory (:mod:`theory.interface`) predicts a fractured transmitted
wave for γ_c0 > 1 and a squeezed one for γ_c0 < 1 (Eq. 9), a compressive reflected
wave for γ_RG > 1 and an expansive one for γ_RG < 1 (Eq. 13), and neither effect on the
lines themselves ("none").  For every classified point of a sweep this module compares
the measured ``transmitted`` / ``reflected`` labels with those predictions.

The *disagreement band* around a line is measured in |ln γ|: its half-width is the
largest |ln γ_c0| (resp. |ln γ_RG|) of a point whose transmitted (resp. reflected)
label disagrees with the theory, so every point farther from the line agrees.  Close to
a line the effects are weak (a reflected wave of relative amplitude |γ_RG - 1|/(γ_RG + 1)
falls below a detection threshold), and the fracture/squeeze boundary is not γ_c0 = 1
but the weakly nonlinear one of :func:`fission_parameter`.

Fracture as soliton fission
---------------------------
In grain units the KdV solitary wave of a precompressed chain has a width that depends
only on its relative amplitude A = ξ/ξ0, as W ∝ A^{-1/2} (Eq. 5).  Crossing the
interface, the pulse keeps its duration, so its length in grains is multiplied by
γ_c0, while its relative amplitude is multiplied by the force transmission
T = 2γ_RG/(1 + γ_RG) (Eq. 12; the static force F0, hence δ/δ0 ∝ F/F0, is the same on both
sides).  A sech² pulse of the KdV equation that is q times wider than the soliton of its
amplitude, q = γ_c0 √T, breaks into s solitons with s(s + 1) = 2q² (the classical
inverse-scattering count): one soliton plus a dispersive tail for q < 1 (squeeze), two
or more for q > 1 (fracture).  Only at γ_RG = 1 does q = 1 coincide with γ_c0 = 1: for
γ_RG < 1 the transmitted wave is weaker and fractures only above γ_c0 = √((1+γ_RG)/(2γ_RG)),
for γ_RG > 1 it fractures below γ_c0 = 1 already.  The second soliton's amplitude grows
from zero at q = 1, so a classifier sees it a little above q = 1.
"""

from __future__ import annotations

from collections import Counter
from dataclasses import dataclass, field

import numpy as np

import theory

from .store import SweepResults

__all__ = ["Agreement", "fission_parameter", "predicted_labels", "classification_agreement"]


def fission_parameter(alpha_rho, alpha_kn):
    """Fission parameter q of the transmitted pulse (:func:`theory.fission_parameter`).

    q > 1: the transmitted pulse fissions into a train (fracture); q < 1: squeeze.
    """
    return theory.fission_parameter(alpha_rho, alpha_kn)


def predicted_labels(alpha_rho, alpha_kn, *, tol: float = 1e-9
                     ) -> tuple[np.ndarray, np.ndarray]:
    """Theory's transmitted and reflected labels for arrays of (α_ρ, α_kn).

    Returns two object arrays: ``"fracture"``/``"squeeze"``/``"none"`` and
    ``"compressive"``/``"expansive"``/``"none"`` (``"none"`` within ``tol`` of a line,
    in |ln γ|).
    """
    lc = np.log(np.atleast_1d(theory.gamma_c0(alpha_rho, alpha_kn)))
    lr = np.log(np.atleast_1d(theory.gamma_rg(alpha_rho, alpha_kn)))
    trans = np.where(lc > tol, "fracture", np.where(lc < -tol, "squeeze", "none"))
    refl = np.where(lr > tol, "compressive", np.where(lr < -tol, "expansive", "none"))
    return trans.astype(object), refl.astype(object)


@dataclass
class Agreement:
    """Result of :func:`classification_agreement`.

    Attributes
    ----------
    n_classified : int
        Points with status "ok" (not "unverified", docs/guide/exit_status.md) and
        finite (α_ρ, α_kn).
    fraction_agree, fraction_agree_transmitted, fraction_agree_reflected : float
        Fractions of those points (off the lines, unless ``strict_lines``) whose both /
        transmitted / reflected labels agree.
    band_gamma_c0, band_gamma_rg : float
        Half-widths in |ln γ| of the disagreement bands around γ_c0 = 1 and γ_RG = 1
        (0 if every point agrees).
    grid_step_gamma_c0, grid_step_gamma_rg : float
        Smallest nonzero spacing of the sampled |ln γ| values (the band cannot be
        resolved finer than this).
    n_in_band_c0, n_in_band_rg : int
        Points inside each band (agreeing or not).
    disagreeing : list of dict
        ``id``, ``alpha_rho``, ``alpha_kn``, measured and predicted labels per
        disagreeing point.
    n_on_line_c0, n_on_line_rg : int
        Points on γ_c0 = 1 / γ_RG = 1 (within ``tol``).
    on_line_labels : dict
        Measured labels of those points, counted, per line.
    band_gamma_c0_by_side, band_gamma_rg_by_side : dict
        The band around one line measured separately on each side of the other line
        (keys ``"gamma_RG<1"``, ``"gamma_RG>1"`` resp. ``"gamma_c0<1"``, ``"gamma_c0>1"``):
        e.g. a fracture that is harder to detect when the transmitted wave is weak
        (γ_RG < 1) widens the γ_c0 band on that side only.
    fraction_agree_fission : float
        Fraction of the transmitted labels that agree with the fission criterion
        (fracture for q > 1, squeeze for q < 1; :func:`fission_parameter`).
    band_fission : dict
        Largest ln q of a disagreement on each side (``"q>1"``, ``"q<1"``, as |ln q|).
    """

    n_classified: int
    fraction_agree: float
    fraction_agree_transmitted: float
    fraction_agree_reflected: float
    band_gamma_c0: float
    band_gamma_rg: float
    grid_step_gamma_c0: float
    grid_step_gamma_rg: float
    n_in_band_c0: int
    n_in_band_rg: int
    disagreeing: list[dict] = field(default_factory=list)
    n_on_line_c0: int = 0
    n_on_line_rg: int = 0
    on_line_labels: dict = field(default_factory=dict)
    band_gamma_c0_by_side: dict = field(default_factory=dict)
    band_gamma_rg_by_side: dict = field(default_factory=dict)
    fraction_agree_fission: float = float("nan")
    band_fission: dict = field(default_factory=dict)

    def to_dict(self) -> dict:
        """JSON-able dict."""
        return dict(self.__dict__)

    def summary(self) -> str:
        """A few lines of text."""
        return (
            f"classified points: {self.n_classified}; agree with theory: "
            f"{self.fraction_agree:.1%} (transmitted {self.fraction_agree_transmitted:.1%}, "
            f"reflected {self.fraction_agree_reflected:.1%})\n"
            f"disagreement band around gamma_c0 = 1: |ln gamma_c0| <= "
            f"{self.band_gamma_c0:.3g} (gamma_c0 in [{np.exp(-self.band_gamma_c0):.3g}, "
            f"{np.exp(self.band_gamma_c0):.3g}]; {self.n_in_band_c0} points; grid step "
            f"{self.grid_step_gamma_c0:.3g}); by side: "
            f"{_fmt_sides(self.band_gamma_c0_by_side)}\n"
            f"disagreement band around gamma_RG = 1: |ln gamma_RG| <= "
            f"{self.band_gamma_rg:.3g} (gamma_RG in [{np.exp(-self.band_gamma_rg):.3g}, "
            f"{np.exp(self.band_gamma_rg):.3g}]; {self.n_in_band_rg} points; grid step "
            f"{self.grid_step_gamma_rg:.3g}); by side: "
            f"{_fmt_sides(self.band_gamma_rg_by_side)}\n"
            f"transmitted vs the fission criterion q = gamma_c0 sqrt(2 gamma_RG/(1 + "
            f"gamma_RG)) > 1: {self.fraction_agree_fission:.1%} agree; band |ln q| "
            f"{_fmt_sides(self.band_fission)}\n"
            f"on the lines: gamma_c0 = 1: {self.n_on_line_c0} points "
            f"{self.on_line_labels.get('gamma_c0=1', {})}; gamma_RG = 1: "
            f"{self.n_on_line_rg} points {self.on_line_labels.get('gamma_RG=1', {})}")


def _fmt_sides(bands: dict) -> str:
    return ", ".join(f"{k}: {v:.3g}" for k, v in bands.items()) or "-"


def _grid_step(x: np.ndarray) -> float:
    u = np.unique(np.round(np.abs(x), 12))
    steps = np.diff(u)
    steps = steps[steps > 1e-12]
    return float(steps.min()) if steps.size else float("nan")


def _band(dist: np.ndarray, bad: np.ndarray) -> float:
    return float(dist[bad].max()) if bad.any() else 0.0


def _mean(x: np.ndarray) -> float:
    return float(np.mean(x)) if x.size else float("nan")


def classification_agreement(results: SweepResults, *, tol: float = 1e-9,
                             strict_lines: bool = False) -> Agreement:
    """Compare measured labels with the theory regions and measure the disagreement bands.

    Parameters
    ----------
    results : SweepResults
        A table with columns ``alpha_rho``, ``alpha_kn``, ``status``, ``transmitted``
        and ``reflected``.
    tol : float
        Distance in |ln γ| within which a point lies on a line, where theory predicts
        "none".
    strict_lines : bool
        Require "none" on the lines.  By default points on a line are not compared for
        that label (a classifier must often pick a side there, e.g. fracture vs squeeze
        at γ_c0 = 1); their measured labels are counted in ``on_line_labels``.

    Returns
    -------
    Agreement
    """
    ar = np.asarray(results["alpha_rho"], dtype=float)
    ak = np.asarray(results["alpha_kn"], dtype=float)
    mask = results.ok & np.isfinite(ar) & np.isfinite(ak) & (ar > 0) & (ak > 0)
    if "transmitted" in results:  # a label exists only once the waves separated ("" else)
        mask &= (results["transmitted"] != "") & (results["reflected"] != "")
    if "completed" in results:  # a run cut short is not a measurement of the map
        mask &= np.asarray(results["completed"]) == 1
    n = int(mask.sum())
    if n == 0 or "transmitted" not in results:
        nan = float("nan")
        return Agreement(0, nan, nan, nan, 0.0, 0.0, nan, nan, 0, 0)
    ar, ak = ar[mask], ak[mask]
    ids = results["id"][mask]
    meas_t = results["transmitted"][mask]
    meas_r = results["reflected"][mask]
    pred_t, pred_r = predicted_labels(ar, ak, tol=tol)
    on_t, on_r = pred_t == "none", pred_r == "none"
    ok_t, ok_r = meas_t == pred_t, meas_r == pred_r
    if not strict_lines:
        ok_t, ok_r = ok_t | on_t, ok_r | on_r
    lc = np.abs(np.log(np.atleast_1d(theory.gamma_c0(ar, ak))))
    lr = np.abs(np.log(np.atleast_1d(theory.gamma_rg(ar, ak))))
    band_c, band_r = _band(lc, ~ok_t), _band(lr, ~ok_r)
    bad = np.flatnonzero(~(ok_t & ok_r))
    disagreeing = [{"id": str(ids[i]), "alpha_rho": float(ar[i]), "alpha_kn": float(ak[i]),
                    "transmitted": str(meas_t[i]), "predicted_transmitted": str(pred_t[i]),
                    "reflected": str(meas_r[i]), "predicted_reflected": str(pred_r[i])}
                   for i in bad]
    counted_t = np.ones(n, bool) if strict_lines else ~on_t
    counted_r = np.ones(n, bool) if strict_lines else ~on_r
    both = counted_t & counted_r
    on_line = {
        "gamma_c0=1": dict(Counter(str(x) for x in meas_t[on_t])),
        "gamma_RG=1": dict(Counter(str(x) for x in meas_r[on_r])),
    }
    sc, sr = np.log(np.atleast_1d(theory.gamma_c0(ar, ak))), \
        np.log(np.atleast_1d(theory.gamma_rg(ar, ak)))
    by_c = {f"gamma_RG{op}1": _band(lc, ~ok_t & side)
            for op, side in (("<", sr < -tol), (">", sr > tol))}
    by_r = {f"gamma_c0{op}1": _band(lr, ~ok_r & side)
            for op, side in (("<", sc < -tol), (">", sc > tol))}
    lq = np.log(np.atleast_1d(fission_parameter(ar, ak)))
    ok_q = meas_t == np.where(lq > 0, "fracture", "squeeze")
    band_q = {"q>1": _band(np.abs(lq), ~ok_q & (lq > 0)),
              "q<1": _band(np.abs(lq), ~ok_q & (lq < 0))}
    return Agreement(
        n_classified=n,
        fraction_agree=_mean((ok_t & ok_r)[both]),
        fraction_agree_transmitted=_mean(ok_t[counted_t]),
        fraction_agree_reflected=_mean(ok_r[counted_r]),
        band_gamma_c0=band_c,
        band_gamma_rg=band_r,
        grid_step_gamma_c0=_grid_step(lc),
        grid_step_gamma_rg=_grid_step(lr),
        n_in_band_c0=int(np.count_nonzero(lc <= band_c)) if band_c > 0 else 0,
        n_in_band_rg=int(np.count_nonzero(lr <= band_r)) if band_r > 0 else 0,
        disagreeing=disagreeing,
        n_on_line_c0=int(on_t.sum()),
        n_on_line_rg=int(on_r.sum()),
        on_line_labels=on_line,
        band_gamma_c0_by_side=by_c,
        band_gamma_rg_by_side=by_r,
        fraction_agree_fission=_mean(ok_q),
        band_fission=band_q,
    )
