#!/usr/bin/env python3
"""Compare two engines with the reference on a shipped scene, print the table, save two of the report's figures."""
from pathlib import Path

import matplotlib

matplotlib.use("Agg")  # files, no window
import tippe

repo = Path(__file__).resolve().parents[2]
scene = repo / "harness/scenes/toy_viscous.toml"

# 2 s of the 6 s scene keeps it quick; drop `set` for the whole run (it inverts at 4.33 s).
c = tippe.compare(scene, engines=["ode", "mujoco"], set=["run.duration=2"], cache=None)
print(c)  # the table `tippe compare` prints
print(c.to_pandas()[["status", "tilt_rms_error", "energy_max_error", "cpu_seconds"]])

for figure in ["theta", "energy_error"]:
    ax = c.plot(figure)
    ax.figure.savefig(f"{scene.stem}-{figure}.png", dpi=80)
    print(f"wrote {scene.stem}-{figure}.png")
