"""Teleoperators on four device pairs: for each architecture the pair's
sensors allow, the largest proven gain at one tick each way, what the
operator feels through it, `verify` at that gain and 5% past it, and the
longest channel 80% of that gain stays proven across.

    python teleop_table.py          (from the repository's root)

It prints a Markdown table (docs/teleoperation.md quotes it) and takes a
few minutes: every cell is a proof or a search of the exact loop."""

import pathlib

import twoport

ROOT = pathlib.Path(__file__).resolve().parents[3]
PAIRS = [
    ("capstan", "capstan"),
    ("two_mass", "two_mass"),
    ("excalibur", "two_mass"),
    ("two_mass", "excalibur"),
]
FORCE_SENSED = {"capstan": False, "two_mass": True, "excalibur": True}


def model(name):
    return str(ROOT / "models" / f"{name}.toml")


def laws(master, slave):
    """(architecture, the gain's name, law at a gain, the largest proven
    gain at one tick) for each law the pair's sensors allow."""
    m, s = model(master), model(slave)
    pp = twoport.design_teleop(m, s, b=0.5, delay=1).gains.k_m_npm
    yield ("position-position", "k (N/m)",
           lambda k: twoport.TeleopGains(k_m_npm=k, k_s_npm=k, b_m_nspm=0.5, b_s_nspm=0.5), pp)
    if FORCE_SENSED[slave]:
        k = 0.5 * pp
        pf = twoport.design_teleop(m, s, b=0.5, k=k, b_m=0.5, delay=1).gains.c2
        yield ("force reflection", "k_f",
               lambda c: twoport.TeleopGains(k_s_npm=k, b_s_nspm=0.5, b_local_nspm=0.5, c2=c), pf)
    if FORCE_SENSED[slave] and FORCE_SENSED[master]:
        k = 0.5 * pp
        four = lambda c: twoport.TeleopGains(k_m_npm=k, k_s_npm=k, b_m_nspm=0.5, b_s_nspm=0.5, c2=c, c3=c)
        lo, hi = 0.0, 1.0
        while hi - lo > 1e-3 * max(lo, 1e-4):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if twoport.check_teleop(m, s, four(mid), delay=1).proven else (lo, mid)
        yield ("four channels", "c2 = c3", four, lo)
    yield ("wave, filter 0.9", "b (N s/m)",
           lambda b: twoport.WaveLaw(b=b, filter_pole=0.9), 0.5)


def longest_delay(m, s, law, most=64):
    """The longest channel (ticks) up to `most` the law stays proven
    across, by doubling then bisection from one tick."""
    proven = lambda d: twoport.check_teleop(m, s, law, delay=d).proven
    lo, hi = 1, 2
    while hi <= most and proven(hi):
        lo, hi = hi, 2 * hi
    if hi > most:
        return f">= {most}"
    while hi - lo > 1:
        mid = (lo + hi) // 2
        lo, hi = (mid, hi) if proven(mid) else (lo, mid)
    return str(lo)


def main():
    print("| pair | law | proven at 1 tick | felt: free mass, damping; wall | "
          "verify at it | 5% past | 80% of it proven up to (ticks) |")
    print("| --- | --- | --- | --- | --- | --- | --- |")
    for master, slave in PAIRS:
        m, s = model(master), model(slave)
        for name, unit, at, gain in laws(master, slave):
            proof = twoport.check_teleop(m, s, at(gain), delay=1)
            mass, damping, wall = proof.felt
            there = twoport.verify_teleop(m, s, at(gain), delay=1)
            past = twoport.verify_teleop(m, s, at(1.05 * gain), delay=1)
            verdict = lambda v: (f"breaks ({v.frequency_hz:.0f} Hz)" if v.unstable
                                 else f"holds ({v.spectral_radius:.6f})")
            print(f"| {master} to {slave} | {name} | {unit} {gain:.4g} | "
                  f"{mass:.3g} kg, {damping:.3g} N s/m; {wall:.4g} N/m | "
                  f"{verdict(there)} | {verdict(past)} | "
                  f"{longest_delay(m, s, at(0.8 * gain))} |", flush=True)


if __name__ == "__main__":
    main()
