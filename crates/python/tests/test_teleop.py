"""Teleoperators from Python: two models, the four-channel gains and the
channel's delay, searched on the exact sampled loop."""

import numpy as np
import pytest

import twoport


def rigid(mass=0.1, damping=1.0, period_s=1e-3):
    return twoport.Model.from_arrays(
        np.array([[mass]]), np.array([[damping]]), np.array([[0.0]]),
        np.array([[1.0, -1.0]]), np.array([[1.0], [-1.0]]),
        period_s=period_s, peak_force_n=50.0, continuous_force_n=20.0, name="rigid")


def test_position_position_meets_colgates_edge_for_the_relative_motion():
    # Two rigid 0.1 kg, 1 N s/m handles: their relative motion holds below
    # k = b / T = 1,000 N/m and grows above it; a delay breaks it below.
    m, s = rigid(), rigid()
    below = twoport.verify_teleop(m, s, k_m=980.0, k_s=980.0)
    above = twoport.verify_teleop(m, s, k_m=1020.0, k_s=1020.0)
    assert not below.unstable, below
    assert above.unstable and abs(above.frequency_hz - 22.7) < 1.0, above
    assert above.operator == (0.0, 0.0, 0.0)
    late = twoport.verify_teleop(m, s, k_m=980.0, k_s=980.0, delay=4)
    assert late.unstable, late


def test_a_bad_teleoperator_raises_naming_it():
    with pytest.raises(ValueError, match="one period"):
        twoport.verify_teleop(rigid(), rigid(period_s=5e-4), k_m=100.0, k_s=100.0)
    with pytest.raises(ValueError, match="at most 1024"):
        twoport.verify_teleop(rigid(), rigid(), k_m=100.0, k_s=100.0, delay=2000)
    with pytest.raises(ValueError, match="k_m"):
        twoport.verify_teleop(rigid(), rigid(), k_m=-1.0)


def test_the_proof_holds_inside_colgates_edge_and_design_finds_it():
    # The same two handles: proven 2% inside k = b / T, refused 2% past;
    # the stiffest proven coupling is within 0.5% below the edge, and
    # verify finds nothing there.
    m, s = rigid(), rigid()
    inside = twoport.check_teleop(m, s, twoport.TeleopGains(k_m=980.0, k_s=980.0))
    past = twoport.check_teleop(m, s, twoport.TeleopGains(k_m=1020.0, k_s=1020.0))
    assert inside.proven and inside.slack > 0.0, inside
    mass, damping, stiffness = inside.felt
    assert abs(mass - 0.2) < 2e-3 and abs(damping - 2.0) < 0.02, inside.felt
    assert abs(stiffness - 980.0) < 10.0, inside.felt
    assert not past.proven and past.slack < 0.0, past
    best = twoport.design_teleop(m, s, b=0.0)
    assert best is not None and best.proven, best
    assert 995.0 < best.gains.k_m <= 1000.0 and best.gains.k_s == best.gains.k_m, best
    there = twoport.verify_teleop(m, s, k_m=best.gains.k_m, k_s=best.gains.k_s)
    assert not there.unstable, there


def test_a_force_channel_without_a_load_cell_raises():
    with pytest.raises(ValueError, match="load cell"):
        twoport.check_teleop(rigid(), rigid(), twoport.TeleopGains(k_s=100.0, c2=0.5))
