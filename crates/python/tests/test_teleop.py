"""Teleoperators from Python: two models, the four-channel gains and the
channel's delay, searched on the exact sampled loop."""

import pathlib

import numpy as np
import pytest

import twoport

ROOT = pathlib.Path(__file__).resolve().parents[3]


def rigid(mass=0.1, damping=1.0, period_s=1e-3):
    return twoport.Model.from_arrays(
        np.array([[mass]]), np.array([[damping]]), np.array([[0.0]]),
        np.array([[1.0, -1.0]]), np.array([[1.0], [-1.0]]),
        period_s=period_s, peak_force_n=50.0, continuous_force_n=20.0, name="rigid")


def pp(k, b=0.0):
    return twoport.TeleopGains(k_m_npm=k, k_s_npm=k, b_m_nspm=b, b_s_nspm=b)


def test_position_position_meets_colgates_edge_for_the_relative_motion():
    # Two rigid 0.1 kg, 1 N s/m handles: their relative motion holds below
    # k = b / T = 1,000 N/m and grows above it; a delay breaks it below.
    m, s = rigid(), rigid()
    below = twoport.verify_teleop(m, s, pp(980.0))
    above = twoport.verify_teleop(m, s, pp(1020.0))
    assert not below.unstable, below
    assert above.unstable and abs(above.frequency_hz - 22.7) < 1.0, above
    assert above.operator == (0.0, 0.0, 0.0)
    late = twoport.verify_teleop(m, s, pp(980.0), delay=4)
    assert late.unstable, late


def test_a_bad_teleoperator_raises_naming_it():
    with pytest.raises(ValueError, match="one period"):
        twoport.verify_teleop(rigid(), rigid(period_s=5e-4), pp(100.0))
    with pytest.raises(ValueError, match="at most 1024"):
        twoport.verify_teleop(rigid(), rigid(), pp(100.0), delay=2000)
    with pytest.raises(ValueError, match="k_m"):
        twoport.verify_teleop(rigid(), rigid(), twoport.TeleopGains(k_m_npm=-1.0))


def test_the_proof_holds_inside_colgates_edge_and_design_finds_it():
    # The same two handles: proven 2% inside k = b / T, refused 2% past;
    # the stiffest proven coupling is within 0.5% below the edge, and
    # verify finds nothing there.
    m, s = rigid(), rigid()
    inside = twoport.check_teleop(m, s, twoport.TeleopGains(k_m_npm=980.0, k_s_npm=980.0))
    past = twoport.check_teleop(m, s, twoport.TeleopGains(k_m_npm=1020.0, k_s_npm=1020.0))
    assert inside.proven and inside.slack > 0.0, inside
    mass, damping, stiffness = inside.felt
    assert abs(mass - 0.2) < 2e-3 and abs(damping - 2.0) < 0.02, inside.felt
    assert abs(stiffness - 980.0) < 10.0, inside.felt
    assert not past.proven and past.slack < 0.0, past
    best = twoport.design_teleop(m, s, b=0.0)
    assert best is not None and best.proven, best
    assert 995.0 < best.gains.k_m_npm <= 1000.0 and best.gains.k_s_npm == best.gains.k_m_npm, best
    there = twoport.verify_teleop(m, s, best.law)
    assert not there.unstable, there


def test_gains_are_named_as_the_scene_files_name_them():
    g = twoport.TeleopGains(k_m_npm=300.0, b_local_nspm=0.5, c3=1.0)
    assert (g.k_m_npm, g.b_local_nspm, g.c3, g.k_s_npm) == (300.0, 0.5, 1.0, 0.0)
    with pytest.raises(TypeError, match="no gain `k_m`; the gains are k_m_npm"):
        twoport.TeleopGains(k_m=300.0)
    with pytest.raises(AttributeError, match="no `k_q`"):
        g.k_q


def test_a_force_channel_without_a_load_cell_raises():
    with pytest.raises(ValueError, match="load cell"):
        twoport.check_teleop(rigid(), rigid(), twoport.TeleopGains(k_s_npm=100.0, c2=0.5))


def test_a_filtered_wave_channel_is_proven_and_a_bare_one_breaks():
    # Two capstan handles, one tick each way: waves low-passed at 0.9 are
    # proven and the search finds nothing; bare, the line resonates with a
    # stiff termination at Nyquist.
    capstan = str(ROOT / "models" / "capstan.toml")
    filtered = twoport.WaveLaw(b=0.5, filter_pole=0.9)
    proof = twoport.check_teleop(capstan, capstan, filtered, delay=1)
    assert proof.proven and proof.gains is None, proof
    assert proof.law.b == 0.5 and abs(proof.law.filter_pole - 0.9) < 1e-6, proof.law
    mass, damping, stiffness = proof.felt
    assert 0.3 < mass < 0.6 and stiffness > 0.0, proof.felt
    assert not twoport.verify_teleop(capstan, capstan, filtered, delay=1).unstable
    bare = twoport.WaveLaw(b=0.5)
    assert not twoport.check_teleop(capstan, capstan, bare, delay=1).proven
    assert twoport.verify_teleop(capstan, capstan, bare, delay=1).unstable
    with pytest.raises(ValueError, match="filter"):
        twoport.check_teleop(capstan, capstan, twoport.WaveLaw(b=0.5, filter_pole=1.5), delay=1)


def test_design_finds_the_wave_channels_largest_proven_impedance():
    capstan = str(ROOT / "models" / "capstan.toml")
    best = twoport.design_teleop(capstan, capstan, filter_pole=0.9, delay=1)
    assert best is not None and best.proven and best.gains is None, best
    assert 1.0 < best.law.b < 3.0 and abs(best.law.filter_pole - 0.9) < 1e-6, best.law
    past = twoport.WaveLaw(b=1.05 * best.law.b, filter_pole=0.9)
    assert not twoport.check_teleop(capstan, capstan, past, delay=1).proven
    assert twoport.design_teleop(capstan, capstan, filter_pole=0.0, delay=1) is None
    with pytest.raises(ValueError, match="filter_pole alone"):
        twoport.design_teleop(capstan, capstan, b=0.5, filter_pole=0.9, delay=1)
