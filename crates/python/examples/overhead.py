"""The Python overhead of a design: `twoport.design_impedance` on a model
file at b 90, timed from Python as `crates/design/examples/design_call.rs`
times the same work from Rust (20 warm-up calls, then the median of 15
runs of 20). `cargo xtask overhead` runs both in turns and gives the
ratio; the goal is at most 5% more from Python."""

import pathlib
import statistics
import sys
import time

import twoport

MODEL = (sys.argv[1] if len(sys.argv) > 1 else
         str(pathlib.Path(__file__).resolve().parents[3] / "models" / "excalibur.toml"))

for _ in range(20):
    twoport.design_impedance(MODEL, b=90.0)
runs = []
for _ in range(15):
    t = time.perf_counter()
    for _ in range(20):
        twoport.design_impedance(MODEL, b=90.0)
    runs.append((time.perf_counter() - t) / 20)
print(f"median_s {statistics.median(runs):.6e}")
