"""A sweep that outgrows one machine: shards of msp.sweep under Dask.

Each task runs one shard (the runs whose index is i modulo n) with
msp.sweep(..., shard=(i, n)); the pieces concatenate back in index order. Here
Dask runs locally on threads (msp releases the GIL while it simulates); on a
cluster the same graph goes to a distributed scheduler unchanged.
Writes dask_sweep.png: the stability region of the Karan-Dey MSP.
"""

import pathlib
import sys

import matplotlib.pyplot as plt
import numpy as np

import dask

import msp

out = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else ".")
N = 4
common = dict(controller="karan-dey", gain="-30%..+30%", delay="-30%..+30%", grid=25, ts=0.074, duration=100)


@dask.delayed
def shard(i):
    return msp.sweep("0.2/s*e^-7.4s", shard=(i, N), **common)


parts = dask.compute(*[shard(i) for i in range(N)], scheduler="threads")
cols = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
order = np.argsort(cols["index"])
cols = {k: v[order] for k, v in cols.items()}
whole = msp.sweep("0.2/s*e^-7.4s", **common)
assert all(np.array_equal(cols[k], whole[k], equal_nan=True) for k in whole if k != "stable")
assert np.array_equal(cols["stable"], whole["stable"])

fig, ax = plt.subplots(figsize=(6, 5))
ok = cols["stable"]
ax.scatter(100 * cols["gain"][ok], 100 * cols["delay"][ok], s=8, c="tab:green", label="stable")
ax.scatter(100 * cols["gain"][~ok], 100 * cols["delay"][~ok], s=8, c="tab:red", label="unstable")
ax.set_xlabel("gain change (%)")
ax.set_ylabel("dead-time change (%)")
ax.set_title("Karan-Dey MSP on 0.2/s e^-7.4s: stability region")
ax.legend()
fig.savefig(out / "dask_sweep.png", dpi=90)
