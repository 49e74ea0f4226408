#!/usr/bin/env python3
"""A small work-precision sweep from a dict, its records as a pandas pivot table (setup x time step)."""
from pathlib import Path

import tippe

repo = Path(__file__).resolve().parents[2]
sweep = {
    "description": "ODE and MuJoCo at three time steps on toy_viscous, 1 s",
    "scenes": [{"file": str(repo / "harness/scenes/toy_viscous.toml"), "duration": 1.0}],
    "setup": [
        {"name": "ode", "engine": "ode", "ladder": {"key": "engines.ode.timestep", "values": [2e-3, 1e-3, 5e-4]}},
        {"name": "mujoco", "engine": "mujoco",
         "ladder": {"key": "engines.mujoco.timestep", "values": [2e-3, 1e-3, 5e-4]}},
    ],
}
result = tippe.sweep(sweep, out="out/pivot-sweep", restart=True)
df = result.to_pandas()
table = df.pivot_table(index="setup", columns="ladder_value", values="metrics.tilt_rms_error")
print(f"{result.points} points; tilt RMS error (rad) against the reference:")
print(table.to_string(float_format=lambda v: f"{v:.3g}"))
