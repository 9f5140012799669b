"""A wall from Python: open a board, home it, hand the VE to this script,
arm, render a wall at 5 mm (solid above) at 1 kHz for two seconds against
whatever pushes the handle, and disarm.

    python wall.py PTY    the board at a serial port (the firmware in QEMU:
                          `cargo xtask device` prints its pty)
    python wall.py        the Excalibur image on a simulated device,
                          in-process
    python wall.py --device NAME PATH [FILE]
                          a device the PC drives, by name (`twoport devices`
                          lists them; FILE: a Falcon's firmware, a Touch's
                          HD library): calibrated where the handle is held,
                          at its image's rest pose, then armed against the
                          image's own wall 5 mm under it for two seconds

Exits 0 when the handle rests on the wall, pressed in by the coupling's
spring, with no fault (a device: armed two seconds with no fault); 1
otherwise, saying why. The servo loop runs on the
board; Python sends a surface every millisecond and waits in `run_for`,
which serves the link with the GIL released."""

import sys
import time

import twoport

WALL_M = 0.005
VE_PERIOD_S = 0.001


def device(name, path, file=None):
    """Calibrate the device at its rest pose, arm it on its image's wall
    for two seconds, disarm; 0 when it stayed armed with no fault."""
    rest = twoport.Board.rest_pose(name)
    b = twoport.Board.device(name, path, file)
    print(f"{name}: {len(rest)} axes; calibrating with the handle at the rest pose")
    b.calibrate(rest)
    b.stream(10)
    b.run_for(0.1)
    start = b.latest()["position_m"][-1]
    b.arm()
    b.run_for(2.0)
    s = b.latest()
    b.disarm()
    b.close()
    print(f"handle {1e3 * (start - s['position_m'][-1]):.2f} mm below the rest pose "
          f"(the wall is at 5 mm), force {s['actuator_n'][-1]:.3f} N, faults {s['faults']}")
    if s["mode"] != "armed" or s["faults"] != 0:
        print("wall: the device did not stay armed without a fault", file=sys.stderr)
        return 1
    print(f"wall: {name} armed for 2 s")
    return 0


if len(sys.argv) > 1 and sys.argv[1] == "--device":
    if not 4 <= len(sys.argv) <= 5:
        print("usage: wall.py --device NAME PATH [FILE]", file=sys.stderr)
        sys.exit(2)
    sys.exit(device(*sys.argv[2:]))

b = twoport.Board.serial(sys.argv[1]) if len(sys.argv) > 1 else twoport.Board.simulated(2.0)
spec = b.spec()
axis = spec["axes"][0]
print(f"board: {len(spec['axes'])} axis, {spec['period_s']:.4f} s period, "
      f"proven up to {axis['k_max_npm']:.0f} N/m at {axis['b_at_limit_nspm']:.1f} N s/m")
b.home(30.0)
b.stream(1)
b.run_for(0.05)
print(f"homed: handle at {b.latest()['position_m'][0]:.6f} m")
# Each surface reached in one tick; up to half a second on one update (a
# board in QEMU shares the machine with this script).
b.host_ve(1, 500)
b.arm()
start = time.monotonic()
due = start
sent = 0
while time.monotonic() - start < 2.0:
    sent = b.send_ve([WALL_M], ["above"])
    due += VE_PERIOD_S
    b.run_for(max(0.0, due - time.monotonic()))
s = b.latest()
b.disarm()
b.close()
x = s["position_m"][0]
print(f"handle at {x:.6f} m, force {s['actuator_n'][0]:.3f} N, faults {s['faults']}, "
      f"update {s['ve_seq']} of {sent} held")
# The hand's 2 N presses the 43,500 N/m coupling 46 um into the wall.
press = 2.0 / 43500.0
if s["mode"] != "armed" or s["faults"] != 0 or abs(x - WALL_M - press) > 20e-6:
    print("wall: the handle did not rest on the wall", file=sys.stderr)
    sys.exit(1)
print(f"wall: held, {sent} updates in 2 s")
