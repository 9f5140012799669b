"""The Python overhead of a design: `twoport.design_impedance` on the
Excalibur's model file at b 90, timed from Python. Compare it with the
criterion bench that does the same work in Rust (`cargo bench --bench
designer -- "as the Python call"`); the goal is at most 5% more."""

import pathlib
import statistics
import time

import twoport

MODEL = str(pathlib.Path(__file__).resolve().parents[3] / "models" / "excalibur.toml")

for _ in range(20):
    twoport.design_impedance(MODEL, b=90.0)
runs = []
for _ in range(15):
    t = time.perf_counter()
    for _ in range(20):
        twoport.design_impedance(MODEL, b=90.0)
    runs.append((time.perf_counter() - t) / 20)
print(f"design_impedance from Python: median {statistics.median(runs) * 1e3:.3f} ms "
      f"(min {min(runs) * 1e3:.3f}, max {max(runs) * 1e3:.3f}) over {len(runs)} runs of 20")
