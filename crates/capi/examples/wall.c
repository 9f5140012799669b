/* A wall from the host: open a board, home it, arm it, render a wall at 5 mm
 * (solid above) from this program for two seconds against whatever pushes
 * the handle, and disarm.
 *
 *   wall PTY    the board at a serial port (the firmware in QEMU:
 *               `cargo xtask device` prints its pty)
 *   wall        the Excalibur image on a simulated device, in-process
 *   wall --device NAME PATH [FILE]
 *               a device the PC drives, by name (`twoport devices` lists
 *               them; FILE: a Falcon's firmware, a Touch's HD library):
 *               calibrated where the handle is held, at its image's rest
 *               pose, then armed against the image's own wall 5 mm under
 *               it for two seconds
 *
 * Exits 0 when the handle rests on the wall, pressed in by the coupling's
 * spring, with no fault (a device: armed two seconds with no fault); 1
 * otherwise, saying why. */

#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "twoport.h"

static const double WALL_M = 0.005;

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

/* Say what failed and why, disarm and free the board, and fail. */
static int fail(TpBoard *b, const char *what) {
    fprintf(stderr, "wall: %s: %s\n", what, tp_last_error());
    tp_board_close(b);
    return 1;
}

/* Serve the link for `seconds`, a millisecond between polls. */
static int poll_for(TpBoard *b, double seconds) {
    double start = now_s();
    while (now_s() - start < seconds) {
        size_t n = 0;
        if (tp_board_poll(b, &n) != TP_RESULT_OK) return 1;
        struct timespec ms = {0, 1000000};
        nanosleep(&ms, NULL);
    }
    return 0;
}

/* A device by name: calibrate at its rest pose, arm, two seconds on its
 * image's wall, disarm. */
static int device(const char *name, const char *path, const char *file) {
    double rest[TP_MAX_AXES];
    size_t axes = 0;
    if (tp_device_rest_pose(name, rest, TP_MAX_AXES, &axes) != TP_RESULT_OK) {
        fprintf(stderr, "wall: %s: %s\n", name, tp_last_error());
        return 1;
    }
    TpBoard *b = NULL;
    if (tp_board_open_device(name, path, file, &b) != TP_RESULT_OK) {
        fprintf(stderr, "wall: open %s: %s\n", name, tp_last_error());
        return 1;
    }
    printf("%s: %zu axes; calibrating with the handle at the rest pose\n", name, axes);
    if (tp_board_calibrate(b, rest, axes) != TP_RESULT_OK) return fail(b, "calibrate");
    if (tp_board_stream(b, 10) != TP_RESULT_OK) return fail(b, "stream");
    if (poll_for(b, 0.1) != 0) return fail(b, "poll");
    TpState s;
    if (tp_board_latest(b, &s) != TP_RESULT_OK) return fail(b, "latest");
    double from = s.axis[axes - 1].position_m;
    if (tp_board_arm(b) != TP_RESULT_OK) return fail(b, "arm");
    if (poll_for(b, 2.0) != 0) return fail(b, "poll");
    if (tp_board_latest(b, &s) != TP_RESULT_OK) return fail(b, "latest");
    printf("handle %.2f mm below the rest pose (the wall is at 5 mm), force %.3f N, "
           "faults %u\n",
           1e3 * (from - s.axis[axes - 1].position_m), s.axis[axes - 1].actuator_n,
           (unsigned)s.faults);
    if (tp_board_disarm(b) != TP_RESULT_OK) return fail(b, "disarm");
    if (tp_board_close(b) != TP_RESULT_OK) {
        fprintf(stderr, "wall: close: %s\n", tp_last_error());
        return 1;
    }
    if (s.mode != TP_MODE_ARMED || s.faults != 0) {
        fprintf(stderr, "wall: the device did not stay armed without a fault\n");
        return 1;
    }
    printf("wall: %s armed for 2 s\n", name);
    return 0;
}

int main(int argc, char **argv) {
    if (argc > 1 && strcmp(argv[1], "--device") == 0) {
        if (argc < 4 || argc > 5) {
            fprintf(stderr, "usage: wall --device NAME PATH [FILE]\n");
            return 2;
        }
        return device(argv[2], argv[3], argc == 5 ? argv[4] : NULL);
    }
    TpBoard *b = NULL;
    TpResult r = argc > 1 ? tp_board_open_serial(argv[1], 1, &b)
                          : tp_board_open_simulated(2.0f, &b);
    if (r != TP_RESULT_OK) {
        fprintf(stderr, "wall: open: %s\n", tp_last_error());
        return 1;
    }
    TpSpec spec;
    if (tp_board_spec(b, &spec) != TP_RESULT_OK) return fail(b, "spec");
    printf("board: %u axis, %.4f s period, proven up to %.0f N/m at %.1f N s/m\n",
           (unsigned)spec.axes, spec.period_s, spec.axis[0].limit,
           spec.axis[0].b_at_limit_nspm);

    /* Into the stop and back out calibrated: at most 30 s. */
    if (tp_board_home(b, 30.0) != TP_RESULT_OK) return fail(b, "home");
    if (tp_board_stream(b, 1) != TP_RESULT_OK) return fail(b, "stream");
    /* Surfaces reached in one tick; up to half a second on one update (a
     * board in QEMU shares the machine with this program). */
    if (tp_board_host_ve(b, 1, 500) != TP_RESULT_OK) return fail(b, "host_ve");
    if (tp_board_arm(b) != TP_RESULT_OK) return fail(b, "arm");

    const uint8_t above = TP_CONTACT_ABOVE;
    double start = now_s();
    while (now_s() - start < 2.0) {
        size_t n = 0;
        if (tp_board_poll(b, &n) != TP_RESULT_OK) return fail(b, "poll");
        if (n > 0 && tp_board_send_ve(b, &WALL_M, &above, 1, NULL) != TP_RESULT_OK)
            return fail(b, "send_ve");
    }

    TpState s;
    if (tp_board_latest(b, &s) != TP_RESULT_OK) return fail(b, "latest");
    double x = s.axis[0].position_m;
    printf("handle at %.6f m, force %.3f N, faults %u, update %u held\n", x,
           s.axis[0].actuator_n, (unsigned)s.faults, (unsigned)s.ve_seq);
    if (tp_board_disarm(b) != TP_RESULT_OK) return fail(b, "disarm");
    if (tp_board_close(b) != TP_RESULT_OK) {
        fprintf(stderr, "wall: close: %s\n", tp_last_error());
        return 1;
    }
    /* The hand's 2 N presses the 43,500 N/m coupling 46 um into the wall. */
    double press = 2.0 / 43500.0;
    if (s.mode != TP_MODE_ARMED || s.faults != 0 || fabs(x - WALL_M - press) > 20e-6) {
        fprintf(stderr, "wall: the handle did not rest on the wall\n");
        return 1;
    }
    printf("wall: held\n");
    return 0;
}
