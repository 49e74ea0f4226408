#!/usr/bin/env python3
"""Import a MuJoCo model (MJCF) as a scene, run it on its own MuJoCo model, and ask which ODE settings keep it safe."""
from pathlib import Path

import tippe

repo = Path(__file__).resolve().parents[2]
model = repo / "docs/advise-example-top.xml"  # your own MJCF here

scene = tippe.import_mjcf(model, out="my_top.toml")
print(f"imported {scene.name}: R = {scene.body.sphere_radius} m, mu = {scene.contact.mu}")

# The model as written, on MuJoCo, against the reference (0.3 s: a quick look).
run = tippe.run(scene, "mujoco", set=["run.duration=0.3"], progress=False)
print(f"mujoco: status {run.status}, tilt {run.final_tilt:.4f} rad after {run.final_time} s")

# A small search (12 runs, 0.3 s of the scene); `tippe advise` defaults are 400 runs, the whole scene.
advice = tippe.advise(scene, out="out/my_top-advice", engines=["ode"], max_runs=12, duration=0.3,
                      step_from=1e-3, resolution=0.3)
print(advice)  # the lines `tippe advise` prints
for e in advice.engines:
    if e.advised_step is not None:
        print(f"{e.engine}: set {', '.join(e.settings)}")  # the cost knob's advised value last
