"""The walk-through of docs/python.md as one script: design a coupling,
check it two ways, see the impedance range the hand feels, simulate the
default scene, prove a host body, and draw it all (matplotlib, when it
is installed) into docs/figures/python-walkthrough.png."""

import pathlib

import numpy as np

import twoport

ROOT = pathlib.Path(__file__).resolve().parents[3]
EXCALIBUR = str(ROOT / "models" / "excalibur.toml")

# 1. Design: the best proven coupling, and the one at the paper's damping.
best = twoport.design_impedance(EXCALIBUR)
paper = twoport.design_impedance(EXCALIBUR, b=90.0)
print(best)
print(paper, "recommended", round(paper.recommended_k_c_npm))

# 2. Check it, and let verify try to break it on the exact sampled loop.
print(twoport.check_impedance(paper.recommended_k_c_npm, 90.0, model=EXCALIBUR))
print(twoport.verify(k=paper.recommended_k_c_npm, b=90.0, model=EXCALIBUR))

# 3. The region: the stiffest proven coupling at each damping.
region = twoport.region(EXCALIBUR, b_from=10.0, b_to=500.0, points=24)

# 4. The impedance range the hand can feel through that coupling.
z = twoport.zrange(paper.recommended_k_c_npm, 90.0, model=EXCALIBUR, points=200)

# 5. The default scene (the hand pushing into a stiff wall), as arrays.
signals, report = twoport.simulate(str(ROOT / "scenes" / "stiff_wall.toml"))
print({k: report[k] for k in ("scene", "stable", "peak_force_n", "energy_in_j")})

# 6. A model from arrays: a rigid 1 kg, 20 N s/m handle; Colgate's
#    k < 2 (20 - b)/T is what the designer finds.
rigid = twoport.Model.from_arrays(
    [[1.0]], [[20.0]], [[0.0]], [[1.0, -1.0]], [[1.0], [-1.0]],
    period_s=1e-3, peak_force_n=50.0, continuous_force_n=20.0, name="rigid handle")
print(twoport.design_impedance(rigid, b=5.0, human=False))

# 7. A body the host moves, at 1 kHz and 2 ms: how much damping it needs.
print(twoport.host_ve(paper.recommended_k_c_npm, 90.0, (1.0, 10.0), model=EXCALIBUR))
print(twoport.host_ve(20_000.0, 60.0, (1.0, 10.0), model=EXCALIBUR))

try:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
except ImportError:
    plt = None
if plt is not None:
    fig, ax = plt.subplots(1, 3, figsize=(13, 3.8))
    ax[0].loglog(region["b_nspm"], region["k_max_npm"], "b-")
    ax[0].plot([paper.b_c_nspm], [paper.k_c_npm], "ro")
    ax[0].set(xlabel="coupling damping b (N s/m)", ylabel="stiffest proven k (N/m)",
              title="The proven region")
    ax[1].loglog(z["frequency_hz"], np.abs(z["z_min"]), label="|Z_min|")
    ax[1].loglog(z["frequency_hz"], np.abs(z["z_max"]), label="|Z_max|")
    ax[1].set(xlabel="frequency (Hz)", ylabel="N s/m", title="What the hand can feel")
    ax[1].legend()
    ax[2].plot(signals["t_s"], 1e3 * signals["handle_m"][:, 0], "k-", lw=0.8)
    ax[2].axhline(10.0, color="r", lw=0.8)
    ax[2].set(xlabel="time (s)", ylabel="handle (mm)", title=report["scene"])
    fig.tight_layout()
    out = ROOT / "docs" / "figures" / "python-walkthrough.png"
    fig.savefig(out, dpi=110)
    print("wrote", out.relative_to(ROOT))
