"""The Dask campaign example runs across processes: each shipped device's
recommended design, verified on the exact loop, holds."""

import importlib.util
import pathlib

ROOT = pathlib.Path(__file__).resolve().parents[3]


def test_the_campaign_verifies_every_design_across_processes():
    spec = importlib.util.spec_from_file_location(
        "campaign", ROOT / "crates" / "python" / "examples" / "campaign.py")
    campaign = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(campaign)
    models = [str(ROOT / "models" / m) for m in ("excalibur.toml", "capstan.toml")]
    rows = campaign.campaign(models, [1000.0, 2000.0], scheduler="processes")
    assert [(r["model"], r["rate_hz"]) for r in rows] == [
        ("excalibur", 1000.0), ("excalibur", 2000.0), ("capstan", 1000.0), ("capstan", 2000.0)]
    for r in rows:
        assert not r["unstable"] and r["spectral_radius"] <= 1.0 and r["loops"] > 100, r
    # The faster servo proves a stiffer coupling on each device.
    assert rows[1]["k_npm"] > rows[0]["k_npm"] and rows[3]["k_npm"] > rows[2]["k_npm"]
