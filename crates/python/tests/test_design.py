"""The designer from Python: designs, checks, searches and ranges on model
files and on models built from arrays, results as classes and numpy
arrays; and the simulator's scenes as numpy arrays."""

import pathlib

import numpy as np
import pytest

import twoport

ROOT = pathlib.Path(__file__).resolve().parents[3]
EXCALIBUR = str(ROOT / "models" / "excalibur.toml")


def rigid(mass=1.0, damping=20.0):
    return twoport.Model.from_arrays(
        np.array([[mass]]), np.array([[damping]]), np.array([[0.0]]),
        np.array([[1.0, -1.0]]), np.array([[1.0], [-1.0]]),
        period_s=1e-3, peak_force_n=50.0, continuous_force_n=20.0, name="rigid")


def test_a_model_from_arrays_meets_colgates_closed_form():
    # A rigid 1 kg, 20 N s/m device at 1 ms: the coupling at b is proven
    # up to Colgate's k = 2 (20 - b) / T, for any passive human.
    m = rigid()
    assert (m.dof, m.period_s, m.name) == (1, 1e-3, "rigid")
    d = twoport.design_impedance(m, b=5.0, human=False)
    assert abs(d.k_c_npm / 30_000.0 - 1.0) < 0.01, d
    inside = twoport.check_impedance(0.9 * d.k_c_npm, 5.0, model=m, human=False)
    past = twoport.check_impedance(1.1 * d.k_c_npm, 5.0, model=m, human=False)
    assert inside.absolutely_stable and not past.absolutely_stable
    assert abs(inside.boundary_k_c_npm - d.k_c_npm) < 1e-6 * d.k_c_npm
    # verify, independent of the proof, agrees on both sides.
    assert not twoport.verify(k=0.9 * d.k_c_npm, b=5.0, model=m, human=False).unstable
    assert twoport.verify(k=1.5 * d.k_c_npm, b=5.0, model=m, human=False).unstable


def test_a_latency_inside_the_tick_lowers_the_proven_stiffness():
    # Half a tick from sample to force on the rigid device: the proof is
    # below the exact loop's boundary 2 b / ((1 + 0.5)^2 T), and verify,
    # on the loop with the force held half a tick late, agrees on both sides.
    m = twoport.Model.from_arrays(
        [[1.0]], [[20.0]], [[0.0]], [[1.0, -1.0]], [[1.0], [-1.0]],
        period_s=1e-3, peak_force_n=50.0, continuous_force_n=20.0,
        latency_s=0.5e-3, name="late")
    assert m.latency_s == 0.5e-3
    exact = 2 * 20.0 / (1.5 ** 2 * 1e-3)
    d = twoport.design_impedance(m, b=0.0, human=False)
    assert 0.88 * exact <= d.k_c_npm <= exact, d
    assert twoport.design_impedance(rigid(), b=0.0, human=False).k_c_npm > 2 * d.k_c_npm
    assert not twoport.verify(k=d.k_c_npm, b=0.0, model=m, human=False).unstable
    assert twoport.verify(k=1.05 * exact, b=0.0, model=m, human=False).unstable
    with pytest.raises(ValueError, match="latency_s"):
        twoport.Model.from_arrays([[1.0]], [[1.0]], [[0.0]], [[1.0, -1.0]],
                                  [[1.0], [-1.0]], period_s=1e-3, latency_s=-1.0,
                                  peak_force_n=1.0, continuous_force_n=1.0)


def test_bad_arrays_and_arguments_are_named():
    with pytest.raises(ValueError, match="M"):
        twoport.Model.from_arrays([[1.0, 0.0]], [[1.0]], [[0.0]], [[1.0, -1.0]],
                                  [[1.0], [-1.0]], period_s=1e-3,
                                  peak_force_n=1.0, continuous_force_n=1.0)
    with pytest.raises(ValueError, match="period_s = NaN: not a finite number"):
        twoport.Model.from_arrays([[1.0]], [[1.0]], [[0.0]], [[1.0, -1.0]],
                                  [[1.0], [-1.0]], period_s=float("nan"),
                                  peak_force_n=1.0, continuous_force_n=1.0)
    with pytest.raises(ValueError, match=r"K\[0\]\[0\] = inf"):
        twoport.Model.from_arrays([[1.0]], [[1.0]], [[float("inf")]], [[1.0, -1.0]],
                                  [[1.0], [-1.0]], period_s=1e-3,
                                  peak_force_n=1.0, continuous_force_n=1.0)
    with pytest.raises(ValueError, match="give k"):
        twoport.verify(b=1.0)
    with pytest.raises(ValueError, match="points 1"):
        twoport.zrange(1000.0, 10.0, points=1)
    with pytest.raises(ValueError, match="kp and bp"):
        twoport.design_admittance(EXCALIBUR, kp=1000.0)


def test_admittance_zrange_and_region_come_back_as_arrays():
    a = twoport.design_admittance(EXCALIBUR)
    assert a.display == "admittance" and a.m_c_kg > 0 and a.regulator is not None
    kp, bp = a.regulator
    assert twoport.check_admittance(kp, bp, a.recommended_m_c_kg, a.b_c_nspm, model=EXCALIBUR).absolutely_stable
    assert not twoport.check_admittance(kp, bp, 0.8 * a.m_c_kg, a.b_c_nspm,
                                        model=EXCALIBUR).absolutely_stable
    ra = twoport.region(EXCALIBUR, b_from=1.0, b_to=50.0, points=6, kp=kp, bp=bp)
    assert ra["m_min_kg"].shape == ra["b_nspm"].shape and np.all(ra["m_min_kg"] > 0)
    za = twoport.zrange(m=a.recommended_m_c_kg, b=a.b_c_nspm, kp=kp, bp=bp, model=EXCALIBUR, points=20)
    assert za["z_max"].shape == (20,)
    z = twoport.zrange(51_000.0, 90.0, model=EXCALIBUR, points=50)
    assert z["frequency_hz"].shape == (50,) and z["z_min"].dtype == np.complex128
    assert np.all(np.isfinite(z["z_min"])) and np.all(np.isfinite(z["z_max"]))
    r = twoport.region(EXCALIBUR, b_from=10.0, b_to=200.0, points=8)
    # A damping with no proven stiffness has no row.
    assert r["b_nspm"].shape == r["k_max_npm"].shape and 6 <= r["b_nspm"].shape[0] <= 8
    assert np.all(np.diff(r["b_nspm"]) > 0) and np.all(r["k_max_npm"] > 0)


def test_a_host_body_is_proven_against_a_soft_coupling_not_the_papers():
    soft = twoport.host_ve(20_000.0, 60.0, (1.0, 10.0), model=EXCALIBUR)
    assert soft.proven and (soft.ve_period_ticks, soft.delay_ticks) == (1, 2)
    stiff = twoport.host_ve(51_000.0, 90.0, (1.0, 10.0), model=EXCALIBUR, verify=True)
    assert not stiff.proven and stiff.least_damping_nspm > 10.0
    assert stiff.verify is not None and stiff.verify.evaluations > 0
    with pytest.raises(ValueError, match="ve_rate 300"):
        twoport.host_ve(20_000.0, 60.0, (1.0, 10.0), ve_rate=300.0)


def test_a_scene_runs_with_overrides_and_comes_back_as_arrays():
    scene = str(ROOT / "scenes" / "stiff_wall.toml")
    s, r = twoport.simulate(scene, ["duration_s=2.0"])
    n = s["t_s"].shape[0]
    assert n == 2000 and s["handle_m"].shape == (n, 1)
    assert r["stable"] and r["sim_seconds"] == pytest.approx(2.0)
    # The hand moves toward the wall at 10 mm and is stopped near it.
    assert 0.005 < s["handle_m"][:, 0].max() < 0.012
    with pytest.raises(ValueError, match="no_such_field"):
        twoport.simulate(scene, ["no_such_field=1"])


def test_a_device_files_axes_and_a_list_of_poses_are_designed_for_together():
    dev = twoport.load_device(str(ROOT / "models" / "devices" / "excalibur_xyz.toml"))
    assert list(dev["axes"]) == ["x", "y", "z"] and len(dev["axes"]["x"]) == 1
    x = twoport.design_impedance(dev["axes"]["x"], b=90.0)
    assert abs(x.k_c_npm - 51_073.0) < 1.0, x
    # Two poses: proven for both, so no stiffer than the softer alone.
    two = str(ROOT / "models" / "two_mass.toml")
    both = twoport.design_impedance([EXCALIBUR, two], b=90.0)
    alone = [twoport.design_impedance(m, b=90.0).k_c_npm for m in (EXCALIBUR, two)]
    assert abs(both.k_c_npm - min(alone)) <= 1e-6 * min(alone), (both, alone)
    with pytest.raises(ValueError, match="empty list"):
        twoport.design_impedance([])
    with pytest.raises(ValueError, match="one pose"):
        twoport.zrange(1000.0, 10.0, model=[EXCALIBUR, two])
    with pytest.raises(ValueError, match="no/such.toml"):
        twoport.load_device("no/such.toml")
