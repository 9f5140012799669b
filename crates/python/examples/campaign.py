"""A verification campaign across processes with Dask: every shipped
lumped device at several servo rates, each designed (the best proven
coupling) and then searched by `verify` on the exact sampled loop for a
hand and VE that break it. Each job is one process's work; the designer
releases the GIL, but `verify` is seconds of Rust per job, so processes
(or a cluster's workers) are what spreads it.

    python campaign.py                      local processes
    python campaign.py tcp://scheduler:8786 the same jobs on a Dask cluster
                                            (needs dask.distributed)

It prints one row per job and exits 1 if `verify` breaks any design."""

import pathlib
import sys

import dask

import twoport

ROOT = pathlib.Path(__file__).resolve().parents[3]
MODELS = ["excalibur.toml", "capstan.toml", "two_mass.toml"]
RATES_HZ = [1000.0, 4000.0]


def job(model: str, rate_hz: float) -> dict:
    """Design the best coupling of `model` at `rate_hz` and verify it."""
    d = twoport.design_impedance(model, period=1.0 / rate_hz, margin=0.1)
    v = twoport.verify(k=d.recommended_k_c_npm, b=d.b_c_nspm, model=model, period=1.0 / rate_hz)
    return {
        "model": pathlib.Path(model).stem,
        "rate_hz": rate_hz,
        "k_npm": d.recommended_k_c_npm,
        "b_nspm": d.b_c_nspm,
        "unstable": v.unstable,
        "spectral_radius": v.spectral_radius,
        "loops": v.evaluations,
    }


def campaign(models=None, rates=None, scheduler="processes"):
    """The jobs as Dask tasks, computed on `scheduler` ("processes", or
    None for a distributed client's cluster); the rows in order."""
    models = models or [str(ROOT / "models" / m) for m in MODELS]
    rates = rates or RATES_HZ
    tasks = [dask.delayed(job)(m, r) for m in models for r in rates]
    (rows,) = dask.compute(tasks, scheduler=scheduler)
    return rows


def main():
    scheduler = "processes"
    if len(sys.argv) > 1:
        from dask.distributed import Client  # only for a cluster

        Client(sys.argv[1])
        scheduler = None
    rows = campaign(scheduler=scheduler)
    for r in rows:
        print(f"{r['model']:>10} {r['rate_hz']:>6.0f} Hz: k {r['k_npm']:>10.0f} N/m at "
              f"b {r['b_nspm']:>7.1f} N s/m; verify: "
              f"{'UNSTABLE' if r['unstable'] else 'nothing found'} "
              f"(radius {r['spectral_radius']:.9f}, {r['loops']} loops)")
    sys.exit(1 if any(r["unstable"] for r in rows) else 0)


if __name__ == "__main__":
    main()
