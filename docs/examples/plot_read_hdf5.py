"""
Reading a result file with h5py
===============================

``hertzchain run SCENARIO.toml --out RUN.h5`` (or :func:`hertzchain.runner.run_scenario`
with ``out=``) writes the whole run to one HDF5 file that carries its parameters.  Here
a short scenario — Table 2's point M on a shorter chain — is run from Python, and the
file is read back with plain h5py, as any other program could.
"""

import json
import tempfile
from pathlib import Path

import h5py
import matplotlib.pyplot as plt
import numpy as np

from hertzchain.runner import run_scenario
from hertzchain.scenario import parse_scenario

scenario = parse_scenario({
    "name": "M-short",
    "chain": {"delta0_over_d": 1e-3, "material": "paper",
              "sections": [{"n": 200}, {"n": 200, "alpha_rho": 0.5,
                                        "alpha_kn": 0.5**1.5}]},
    "initial": {"kind": "exact_wave", "center": 100, "velocity_max": 0.0822},
    "run": {"until_front_at": 330},
    "record": {"energy_every": 200},
})
out = Path(tempfile.mkdtemp()) / "M-short.h5"
run_scenario(scenario, out=out)

# %%
# The file: root attributes (solver, time step, energy drift, the scenario and the
# summary as JSON, the unit of every dataset), the chain, the final state, the record
# (running maxima, energy grid, monitor) and the snapshots.
with h5py.File(out, "r") as f:
    print("root attributes:", sorted(f.attrs))
    f.visititems(lambda name, obj: print(f"  {name} {getattr(obj, 'shape', '')}"))
    units = json.loads(f.attrs["units"])          # unit of every dataset, by name
    print("v in", units["v"], "| k in", units["k"], "| energies in", units["energy_kinetic"])
    summary = json.loads(f.attrs["summary"])     # the run's summary, as printed by the CLI
    print("summary:", {k: summary[k] for k in list(summary)[:6]})
    t = f.attrs["t"]
    v = f["state/v"][:]
    e_t = f["record/energy_t"][:]
    e_kin = f["record/energy_kinetic"][:]         # (time, grain) space-time grid, J

fig, (ax, bx) = plt.subplots(1, 2, figsize=(9, 3.2))
ax.plot(v, lw=1)
ax.axvline(199.5, color="0.5", ls=":")
ax.set(xlabel="grain index $i$", ylabel="v (m/s)", title=f"final state, t = {t * 1e3:.3f} ms")
im = bx.pcolormesh(np.arange(e_kin.shape[1]), e_t * 1e3, e_kin, shading="auto", cmap="magma")
bx.axvline(199.5, color="w", ls=":")
bx.set(xlabel="grain index $i$", ylabel="t (ms)", title="kinetic energy per grain (J)")
fig.colorbar(im, ax=bx)
fig.tight_layout()

# %%
# :func:`discrete.load` reads the same file back into a :class:`discrete.Simulation`
# (which can be continued), and ``hertzchain info RUN.h5`` describes it.
import discrete  # noqa: E402

sim = discrete.load(out)
print(sim.t == t, np.array_equal(sim.v, v))
