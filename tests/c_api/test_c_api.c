// SPDX-License-Identifier: BSD-3-Clause
/* The C API (include/hexatwist/c/hexatwist.h), compiled as C99: models, commands against the
 * report, forward kinematics round trips and tracking, limits, errors, and no allocation in the
 * real-time calls (malloc interposed: every heap allocation of the process is counted). */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "hexatwist/c/hexatwist.h"

static int passed = 0, failed = 0;

#define CHECK(cond, ...)                                                       \
  do {                                                                         \
    if (cond) {                                                                \
      ++passed;                                                                \
    } else {                                                                   \
      ++failed;                                                                \
      fprintf(stderr, "%s:%d: CHECK(%s) failed: ", __FILE__, __LINE__, #cond); \
      fprintf(stderr, __VA_ARGS__);                                            \
      fputc('\n', stderr);                                                     \
    }                                                                          \
  } while (0)

#ifndef HEXATWIST_NO_MALLOC_PROBE
/* glibc's allocator under its own names; the definitions below replace malloc for the whole
 * process, the C++ runtime's operator new included. */
extern void* __libc_malloc(size_t);
extern void* __libc_calloc(size_t, size_t);
extern void* __libc_realloc(void*, size_t);
extern void __libc_free(void*);
static volatile long allocations = 0;
void* malloc(size_t n) {
  ++allocations;
  return __libc_malloc(n);
}
void* calloc(size_t n, size_t m) {
  ++allocations;
  return __libc_calloc(n, m);
}
void* realloc(void* p, size_t n) {
  ++allocations;
  return __libc_realloc(p, n);
}
void free(void* p) { __libc_free(p); }
#define PROBE 1
#else
static long allocations = 0;
#define PROBE 0
#endif

static double max_abs_diff(const double* a, const double* b, int n) {
  double worst = 0.0;
  for (int i = 0; i < n; ++i) worst = fmax(worst, fabs(a[i] - b[i]));
  return worst;
}

static const double kDeg = 3.14159265358979323846 / 180.0;

/* A seeded pseudo-random pose inside the seed's test range: +-0.3 m, +-20 deg. */
static unsigned long long rng_state = 12345;
static double uniform(double lo, double hi) {
  rng_state = rng_state * 6364136223846793005ULL + 1442695040888963407ULL;
  return lo + (hi - lo) * (double)(rng_state >> 11) / 9007199254740992.0;
}
static void random_pose(double pose[6]) {
  for (int k = 0; k < 3; ++k) pose[k] = uniform(-0.3, 0.3);
  for (int k = 3; k < 6; ++k) pose[k] = uniform(-20, 20) * kDeg;
}

static void test_models(void) {
  char error[256];
  hexatwist_model* m = hexatwist_model_default(error, sizeof error);
  CHECK(m != NULL, "default model: %s", error);
  CHECK(strstr(hexatwist_model_name(m), "seed platform") != NULL, "name '%s'", hexatwist_model_name(m));
  CHECK(fabs(hexatwist_model_home_height(m) - 1.511) < 1e-15, "home height %g", hexatwist_model_home_height(m));
  double geometric[6], motor[6], lo, hi;
  hexatwist_model_home_lengths(m, geometric, motor);
  hexatwist_model_stroke(m, &lo, &hi);
  CHECK(lo == 1.4 && hi == 2.45, "stroke %g..%g", lo, hi);
  for (int i = 0; i < 6; ++i)
    CHECK(geometric[i] > lo && geometric[i] < hi && motor[i] == geometric[i], "leg %d", i + 1);
  double reference[6];
  hexatwist_model_home_commands(m, reference);
  for (int i = 0; i < 6; ++i) CHECK(reference[i] == motor[i], "leg %d: reference %g", i + 1, reference[i]);
  hexatwist_model_free(m);
  hexatwist_model_free(NULL);

  /* The drives' reference and scale (an identification's contract): the reference is what the
     configuration says, and the commands move about it by the inverse of the drive scale. */
  m = hexatwist_model_from_yaml(
      "symmetric: {Ra: 1.2, Rb: 1.5, da: 0.2, db: 0.3, H: 1.511}\n"
      "screw: {lead: 0.0102, drive_lead: 0.010, thread: right, driven_side: base}\n"
      "limits: {length_min: 1.4, length_max: 2.45}\n"
      "home_commands: [1.911, 1.912, 1.913, 1.914, 1.915, 1.916]\n",
      "drive.yaml", error, sizeof error);
  CHECK(m != NULL, "drive model: %s", error);
  hexatwist_model_home_commands(m, reference);
  for (int i = 0; i < 6; ++i)
    CHECK(fabs(reference[i] - (1.911 + 0.001 * i)) < 1e-15, "leg %d: %g", i + 1, reference[i]);
  hexatwist_model_free(m);

  /* Errors: one line naming the file, line and field, or the path. */
  m = hexatwist_model_from_yaml("symmetric:\n  Ra: abc\n", "bad.yaml", error, sizeof error);
  CHECK(m == NULL && strstr(error, "bad.yaml:1:1: field 'screw'") == error && !strchr(error, '\n'), "message '%s'",
        error);
  m = hexatwist_model_from_file("/nonexistent/platform.yaml", error, sizeof error);
  CHECK(m == NULL && strstr(error, "/nonexistent/platform.yaml") && strstr(error, "cannot read"), "message '%s'",
        error);
  m = hexatwist_model_from_file(NULL, error, sizeof error);
  CHECK(m == NULL && strstr(error, "NULL"), "message '%s'", error);
  char tiny[8];
  m = hexatwist_model_from_yaml("name: [", "x.yaml", tiny, sizeof tiny);
  CHECK(m == NULL && strlen(tiny) == sizeof tiny - 1, "truncated to the buffer: '%s'", tiny);
  m = hexatwist_model_from_yaml("name: x\n", "x.yaml", NULL, 0); /* no buffer: still NULL, no crash */
  CHECK(m == NULL, "no buffer");

  /* The seed file itself, from disk. */
  m = hexatwist_model_from_file(HEXATWIST_SOURCE_DIR "/configs/seed.yaml", error, sizeof error);
  CHECK(m != NULL, "configs/seed.yaml: %s", error);
  hexatwist_model_free(m);
}

static void test_commands_and_fk(const hexatwist_model* m) {
  double worst_round_trip = 0.0;
  for (int n = 0; n < 500; ++n) {
    double pose[6], comp[6], conv[6];
    random_pose(pose);
    hexatwist_command_report report;
    hexatwist_limit limit;
    const hexatwist_status s = hexatwist_compute_commands(m, pose, &report);
    if (s != HEXATWIST_OK) {
      CHECK(hexatwist_status_is_limit(s), "pose %d: %s", n, hexatwist_status_name(s));
      continue;
    }
    CHECK(hexatwist_motor_commands(m, pose, HEXATWIST_COMPENSATED, comp, &limit) == HEXATWIST_OK, "pose %d", n);
    CHECK(hexatwist_motor_commands(m, pose, HEXATWIST_CONVENTIONAL, conv, &limit) == HEXATWIST_OK, "pose %d", n);
    CHECK(max_abs_diff(comp, report.compensated, 6) < 1e-15, "real-time and full path agree");
    CHECK(max_abs_diff(conv, report.length, 6) < 1e-15, "conventional = length (zero offsets)");
    double twist[6];
    CHECK(hexatwist_twist(m, pose, twist) == HEXATWIST_OK && max_abs_diff(twist, report.twist, 6) == 0.0, "twist");
    for (int i = 0; i < 6; ++i) {
      /* Eq. (10)-(12): the length error is lead * twist / 2 pi, and the command subtracts it. */
      CHECK(fabs(report.length_error[i] - 0.010 * report.twist[i] / (2 * 3.14159265358979323846)) < 1e-15, "Eq. 10");
      CHECK(fabs(report.length[i] - report.length_error[i] - report.compensated[i]) < 1e-15, "Eq. 12");
    }
    CHECK(report.condition >= 1 && report.condition < 50, "condition %g", report.condition);
    CHECK(report.nearest_margin > 0 && report.nearest_margin <= 1, "margin %g", report.nearest_margin);

    hexatwist_fk_result fk;
    CHECK(hexatwist_forward_kinematics(m, comp, HEXATWIST_MOTOR, NULL, NULL, &fk) == HEXATWIST_OK, "fk %d", n);
    worst_round_trip = fmax(worst_round_trip, max_abs_diff(fk.pose, pose, 6));
    CHECK(fk.residual <= 1e-12 && fk.iterations > 0, "residual %g", fk.residual);
    CHECK(hexatwist_forward_kinematics(m, report.length, HEXATWIST_GEOMETRIC, pose, NULL, &fk) == HEXATWIST_OK &&
              max_abs_diff(fk.pose, pose, 6) < 1e-11,
          "geometric fk from the pose itself");
  }
  CHECK(worst_round_trip < 1e-11, "worst round trip %g", worst_round_trip);
  printf("C API: worst FK round trip %.2g (m, rad)\n", worst_round_trip);
}

static void test_limits(const hexatwist_model* m) {
  const double outside[6] = {0, 0, 0.8, 0, 0, 0}; /* legs past their maximum */
  double command[6] = {-1, -1, -1, -1, -1, -1};
  hexatwist_limit limit;
  const hexatwist_status s = hexatwist_motor_commands(m, outside, HEXATWIST_COMPENSATED, command, &limit);
  CHECK(s == HEXATWIST_STROKE_ABOVE_MAX && limit.status == s && limit.leg >= 1 && limit.leg <= 6, "%s leg %d",
        hexatwist_status_name(s), limit.leg);
  CHECK(limit.value > limit.bound && limit.bound == 2.45, "value %g bound %g", limit.value, limit.bound);
  CHECK(command[0] == -1 && command[5] == -1, "no command written outside a limit");
  const double nan_pose[6] = {NAN, 0, 0, 0, 0, 0};
  CHECK(hexatwist_motor_commands(m, nan_pose, HEXATWIST_COMPENSATED, command, NULL) == HEXATWIST_NON_FINITE_INPUT,
        "NaN");
  CHECK(hexatwist_motor_commands(NULL, outside, HEXATWIST_COMPENSATED, command, NULL) == HEXATWIST_INVALID_ARGUMENT,
        "NULL");
  CHECK(hexatwist_motor_commands(m, outside, (hexatwist_strategy)7, command, NULL) == HEXATWIST_INVALID_ARGUMENT,
        "enum");
  hexatwist_fk_result fk;
  CHECK(
      hexatwist_forward_kinematics(m, command, (hexatwist_length_kind)5, NULL, NULL, &fk) == HEXATWIST_INVALID_ARGUMENT,
      "length kind");
  CHECK(strcmp(hexatwist_version(), HEXATWIST_PROJECT_VERSION) == 0, "version %s, CMake's %s", hexatwist_version(),
        HEXATWIST_PROJECT_VERSION);
  CHECK(strcmp(hexatwist_status_name(HEXATWIST_OK), "ok") == 0, "name");
  CHECK(strcmp(hexatwist_status_name(HEXATWIST_PLATFORM_SINGULARITY), "platform_singularity") == 0, "name");
  CHECK(strcmp(hexatwist_status_name(HEXATWIST_INVALID_ARGUMENT), "invalid_argument") == 0, "name");
  CHECK(
      hexatwist_status_is_limit(HEXATWIST_PLATFORM_SINGULARITY) && !hexatwist_status_is_limit(HEXATWIST_NO_CONVERGENCE),
      "is_limit");
  CHECK(strlen(hexatwist_status_describe(HEXATWIST_BEND_BASE)) > 10, "describe");
}

/* A 1 kHz yaw sweep with the tracker: every step solved on home's assembly mode, and the
 * tracker reset or set from a pose behaves as documented. */
static void test_tracking(const hexatwist_model* m) {
  hexatwist_fk_tracker tracker;
  memset(&tracker, 0, sizeof tracker);
  hexatwist_fk_result fk;
  int ok = 0, steps = 0;
  double worst = 0.0;
  for (double yaw = 0; yaw <= 30.0; yaw += 0.015, ++steps) {
    const double pose[6] = {0.1 * sin(yaw * kDeg), 0, 0.05, 0, 0, yaw * kDeg};
    double command[6];
    if (hexatwist_motor_commands(m, pose, HEXATWIST_COMPENSATED, command, NULL) != HEXATWIST_OK) continue;
    ok += hexatwist_forward_kinematics_tracked(m, command, HEXATWIST_MOTOR, &tracker, NULL, &fk) == HEXATWIST_OK;
    worst = fmax(worst, max_abs_diff(fk.pose, pose, 6));
  }
  CHECK(ok == steps && tracker.valid && worst < 1e-11, "%d of %d tracked, worst %g", ok, steps, worst);
  hexatwist_fk_tracker_reset(&tracker);
  CHECK(!tracker.valid, "reset");
  const double at[6] = {0, 0, 0.05, 0, 0, 10 * kDeg};
  CHECK(hexatwist_fk_tracker_set(m, &tracker, at, HEXATWIST_MOTOR) == HEXATWIST_OK && tracker.valid &&
            (tracker.det_sign == 1.0 || tracker.det_sign == -1.0),
        "set");
  hexatwist_fk_options options = hexatwist_fk_default_options();
  CHECK(options.max_iterations > 0 && options.tolerance > 0 && options.max_step_translation > 0, "options");
  options.max_iterations = 1; /* one iteration: the far solve cannot converge, and says so */
  double command[6];
  const double far[6] = {0.2, -0.2, 0.1, 0.1, 0.1, 0.3};
  CHECK(hexatwist_motor_commands(m, far, HEXATWIST_COMPENSATED, command, NULL) == HEXATWIST_OK, "far pose");
  const hexatwist_fk_tracker before = tracker;
  CHECK(hexatwist_forward_kinematics_tracked(m, command, HEXATWIST_MOTOR, &tracker, &options, &fk) ==
                HEXATWIST_NO_CONVERGENCE &&
            memcmp(&before, &tracker, sizeof tracker) == 0,
        "a failed tracked solve leaves the tracker as it was");
}

/* Every call given what a new user tries (#22): NaN, +-inf, 0, -1, 1e300 in each option and
 * argument. Each answers as the library, the CLI and Python do: HEXATWIST_INVALID_ARGUMENT for an
 * option outside its documented range or a length <= 0, HEXATWIST_NON_FINITE_INPUT for NaN or inf
 * in a pose, length or guess; never HEXATWIST_OK with a meaningless result, and a tracker is kept. */
static void test_invalid_arguments(const hexatwist_model* m) {
  const double bad[] = {NAN, INFINITY, -INFINITY, 0.0, -1.0, 1e300};
  double home[6], command[6];
  hexatwist_model_home_commands(m, home);
  hexatwist_fk_result fk;
  hexatwist_fk_tracker tracker;
  memset(&tracker, 0, sizeof tracker);
  const double at[6] = {0, 0, 0.05, 0, 0, 10 * kDeg};
  CHECK(hexatwist_fk_tracker_set(m, &tracker, at, HEXATWIST_MOTOR) == HEXATWIST_OK, "set");
  const hexatwist_fk_tracker kept = tracker;
  for (int field = 0; field < 4; ++field)
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
      hexatwist_fk_options o = hexatwist_fk_default_options();
      const double v = bad[k];
      if (field == 0) o.max_iterations = v == 1e300 ? 1000000 : (int)(isfinite(v) ? v : -1);
      if (field == 1) o.tolerance = v;
      if (field == 2) o.max_step_translation = v;
      if (field == 3) o.max_step_rotation = v;
      const hexatwist_status s = hexatwist_forward_kinematics(m, home, HEXATWIST_MOTOR, NULL, &o, &fk);
      CHECK(s == HEXATWIST_INVALID_ARGUMENT, "option %d = %g: %s", field, v, hexatwist_status_name(s));
      const hexatwist_status t = hexatwist_forward_kinematics_tracked(m, home, HEXATWIST_MOTOR, &tracker, &o, &fk);
      CHECK(t == HEXATWIST_INVALID_ARGUMENT && memcmp(&kept, &tracker, sizeof tracker) == 0,
            "tracked, option %d = %g: %s, tracker kept", field, v, hexatwist_status_name(t));
    }
  /* The case: a loose tolerance no longer passes a 0.3 m residual at home. */
  hexatwist_fk_options loose = hexatwist_fk_default_options();
  loose.tolerance = 0.5;
  double off[6];
  for (int i = 0; i < 6; ++i) off[i] = home[i] + 0.3;
  CHECK(hexatwist_forward_kinematics(m, off, HEXATWIST_MOTOR, NULL, &loose, &fk) == HEXATWIST_INVALID_ARGUMENT,
        "tolerance 0.5 m refused");
  for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k)
    for (int i = 0; i < 6; ++i) {
      double lengths[6], pose[6] = {0, 0, 0, 0, 0, 0};
      memcpy(lengths, home, sizeof lengths);
      lengths[i] = bad[k];
      const int finite = isfinite(bad[k]);
      const hexatwist_status s = hexatwist_forward_kinematics(m, lengths, HEXATWIST_GEOMETRIC, NULL, NULL, &fk);
      const hexatwist_status expected = !finite ? HEXATWIST_NON_FINITE_INPUT : HEXATWIST_INVALID_ARGUMENT;
      CHECK(bad[k] > 0 && finite ? s != HEXATWIST_OK : s == expected, "length %d = %g: %s", i + 1, bad[k],
            hexatwist_status_name(s));
      pose[i] = bad[k];
      const hexatwist_status c = hexatwist_motor_commands(m, pose, HEXATWIST_COMPENSATED, command, NULL);
      CHECK(bad[k] == 0.0 || bad[k] == -1.0 || (c != HEXATWIST_OK && !(c == HEXATWIST_INVALID_ARGUMENT)),
            "pose %d = %g: %s", i + 1, bad[k], hexatwist_status_name(c));
    }
  char error[256];
  CHECK(hexatwist_model_from_file(HEXATWIST_SOURCE_DIR "/configs", error, sizeof error) == NULL &&
            strstr(error, "is a directory") != NULL,
        "a directory: '%s'", error);
  CHECK(hexatwist_model_from_file("/dev/zero", error, sizeof error) == NULL && strstr(error, "longer than") != NULL,
        "an endless file: '%s'", error);
  CHECK(strcmp(hexatwist_status_name(HEXATWIST_INVALID_ARGUMENT), "invalid_argument") == 0, "name");
}

/* The legs' effects (docs/theory/kinematics.md §4b): the defaults are the plain call, warm legs are
   commanded shorter by their growth, a reversal crosses the play, and none of it allocates. */
static void test_leg_effects(void) {
  char error[256];
  hexatwist_model* m = hexatwist_model_from_yaml(
      "symmetric: {Ra: 1.2, Rb: 1.5, da: 0.2, db: 0.3, H: 1.511}\n"
      "screw: {lead: 0.010, thread: right, driven_side: base}\n"
      "limits: {length_min: 1.4, length_max: 2.45}\n"
      "leg_effects: {play: 50.0e-6, length_expansion: 11.5e-6, lead_expansion: 11.0e-6}\n",
      "effects.yaml", error, sizeof error);
  CHECK(m != NULL, "effects model: %s", error);
  if (!m) return;
  double up[6] = {0, 0, 0.1, 0, 0, 0}, down[6] = {0, 0, 0.099, 0, 0, 0};
  double plain[6], under[6], warm[6], plain_down[6], c_up[6], c_down[6];
  hexatwist_limit limit;
  CHECK(hexatwist_motor_commands(m, up, HEXATWIST_COMPENSATED, plain, &limit) == HEXATWIST_OK, "plain");
  CHECK(hexatwist_motor_commands_under(m, up, HEXATWIST_COMPENSATED, NULL, NULL, under, &limit) == HEXATWIST_OK &&
            max_abs_diff(plain, under, 6) == 0.0,
        "the defaults are the plain call's");
  hexatwist_leg_inputs in = hexatwist_leg_inputs_default();
  for (int i = 0; i < 6; ++i) in.temperature[i] = 22.0;
  CHECK(hexatwist_motor_commands_under(m, up, HEXATWIST_COMPENSATED, &in, NULL, warm, &limit) == HEXATWIST_OK, "warm");
  for (int i = 0; i < 6; ++i)
    CHECK(plain[i] - warm[i] > 40e-6 && plain[i] - warm[i] < 50e-6, "leg %d: 2 K shorten the command by %g m", i + 1,
          plain[i] - warm[i]);
  hexatwist_play_state play;
  hexatwist_play_start(m, &play);
  CHECK(hexatwist_motor_commands(m, down, HEXATWIST_COMPENSATED, plain_down, &limit) == HEXATWIST_OK, "plain down");
  const long before = allocations;
  const hexatwist_status s_up = hexatwist_motor_commands_under(m, up, HEXATWIST_COMPENSATED, NULL, &play, c_up, &limit);
  const hexatwist_status s_down =
      hexatwist_motor_commands_under(m, down, HEXATWIST_COMPENSATED, NULL, &play, c_down, &limit);
  CHECK(!PROBE || allocations == before, "%ld allocations in the real-time calls", allocations - before);
  CHECK(s_up == HEXATWIST_OK && s_down == HEXATWIST_OK, "up and down");
  CHECK(max_abs_diff(c_up, plain, 6) == 0.0, "up from home: the homing's side, no play term");
  for (int i = 0; i < 6; ++i) {
    CHECK(play.direction[i] == -1.0, "leg %d: shortening", i + 1);
    CHECK(fabs(c_down[i] - (plain_down[i] - 50e-6)) < 1e-15, "leg %d: the reversal crosses the play (%g)", i + 1,
          c_down[i] - plain_down[i]);
  }
  /* The report and the forward kinematics under the same inputs: the report's command is the
     real-time one, and the warm legs at the warm command stand at the commanded pose (a LinuxCNC
     module's inverse and forward kinematics with a temperature pin). */
  hexatwist_command_report report;
  CHECK(hexatwist_compute_commands_under(m, up, &in, NULL, &report) == HEXATWIST_OK, "report under");
  CHECK(max_abs_diff(report.compensated, warm, 6) < 1e-12, "report's command vs the real-time one: %g",
        max_abs_diff(report.compensated, warm, 6));
  hexatwist_fk_tracker tracker;
  hexatwist_fk_result fk;
  hexatwist_fk_tracker_reset(&tracker);
  const long fk_before = allocations;
  const hexatwist_status s_warm = hexatwist_forward_kinematics_tracked_under(m, warm, &in, NULL, &tracker, NULL, &fk);
  CHECK(!PROBE || allocations == fk_before, "%ld allocations in the tracked forward kinematics",
        allocations - fk_before);
  CHECK(s_warm == HEXATWIST_OK && max_abs_diff(fk.pose, up, 6) < 1e-9, "warm FK of the warm command: %s, %g",
        hexatwist_status_name(s_warm), max_abs_diff(fk.pose, up, 6));
  hexatwist_fk_tracker_reset(&tracker);
  CHECK(hexatwist_forward_kinematics_tracked_under(m, warm, NULL, NULL, &tracker, NULL, &fk) == HEXATWIST_OK &&
            fk.pose[2] < up[2] - 30e-6,
        "the warm command on legs at the reference stands lower: %g m", fk.pose[2] - up[2]);
  in.temperature[0] = 250.0;
  CHECK(hexatwist_compute_commands_under(m, up, &in, NULL, &report) == HEXATWIST_INVALID_ARGUMENT,
        "a temperature above 200 degC in the report");
  CHECK(hexatwist_motor_commands_under(m, up, HEXATWIST_COMPENSATED, &in, NULL, warm, &limit) ==
            HEXATWIST_INVALID_ARGUMENT,
        "a temperature above 200 degC in the command");
  CHECK(hexatwist_forward_kinematics_tracked_under(m, plain, &in, NULL, &tracker, NULL, &fk) ==
            HEXATWIST_INVALID_ARGUMENT,
        "a temperature above 200 degC in the forward kinematics");
  in.temperature[0] = INFINITY;
  CHECK(hexatwist_motor_commands_under(m, up, HEXATWIST_COMPENSATED, &in, NULL, warm, &limit) ==
            HEXATWIST_NON_FINITE_INPUT,
        "an infinite temperature");
  CHECK(hexatwist_motor_commands_under(NULL, up, HEXATWIST_COMPENSATED, NULL, NULL, warm, &limit) ==
            HEXATWIST_INVALID_ARGUMENT,
        "no model");
  /* Without its play (LinuxCNC's BACKLASH takes it): the commands of the same file without the play
     line, bit for bit, its expansions kept. */
  double played[6];
  hexatwist_model* rigid = hexatwist_model_without_play(m, error, sizeof error);
  hexatwist_model* written = hexatwist_model_from_yaml(
      "symmetric: {Ra: 1.2, Rb: 1.5, da: 0.2, db: 0.3, H: 1.511}\n"
      "screw: {lead: 0.010, thread: right, driven_side: base}\n"
      "limits: {length_min: 1.4, length_max: 2.45}\n"
      "leg_effects: {length_expansion: 11.5e-6, lead_expansion: 11.0e-6}\n",
      "no-play.yaml", error, sizeof error);
  CHECK(rigid != NULL && written != NULL, "models without play: %s", error);
  if (rigid && written) {
    CHECK(hexatwist_model_play(m, played) && !hexatwist_model_play(rigid, NULL), "the play is gone");
    CHECK(hexatwist_model_expands(rigid, NULL), "the expansions stay");
    CHECK(hexatwist_motor_commands_under(rigid, down, HEXATWIST_COMPENSATED, NULL, NULL, c_down, &limit) ==
                  HEXATWIST_OK &&
              hexatwist_motor_commands_under(written, down, HEXATWIST_COMPENSATED, NULL, NULL, plain_down, &limit) ==
                  HEXATWIST_OK &&
              max_abs_diff(c_down, plain_down, 6) == 0.0,
          "the commands of the file without its play");
  }
  hexatwist_model_free(rigid);
  hexatwist_model_free(written);
  CHECK(hexatwist_model_without_play(NULL, error, sizeof error) == NULL && strstr(error, "NULL"), "no model: '%s'",
        error);
  hexatwist_model_free(m);
}

static void test_no_allocation(const hexatwist_model* m) {
  if (!PROBE) return;
  char error[64];
  const long probe_before = allocations;
  hexatwist_model* other = hexatwist_model_default(error, sizeof error);
  CHECK(allocations > probe_before, "the probe sees the model's allocations");
  hexatwist_model_free(other);

  hexatwist_fk_tracker tracker;
  memset(&tracker, 0, sizeof tracker);
  const long before = allocations;
  int calls = 0;
  for (int n = 0; n < 200; ++n) {
    double pose[6], command[6], twist[6];
    random_pose(pose);
    if (n % 4 == 0) pose[2] = 1.0; /* outside a limit */
    hexatwist_command_report report;
    hexatwist_fk_result fk;
    hexatwist_limit limit;
    (void)hexatwist_compute_commands(m, pose, &report);
    (void)hexatwist_twist(m, pose, twist);
    if (hexatwist_motor_commands(m, pose, HEXATWIST_COMPENSATED, command, &limit) == HEXATWIST_OK) {
      (void)hexatwist_forward_kinematics(m, command, HEXATWIST_MOTOR, NULL, NULL, &fk);
      (void)hexatwist_forward_kinematics_tracked(m, command, HEXATWIST_MOTOR, &tracker, NULL, &fk);
      (void)hexatwist_fk_tracker_set(m, &tracker, pose, HEXATWIST_MOTOR);
      ++calls;
    }
    (void)hexatwist_status_name(hexatwist_status_is_limit(limit.status) ? limit.status : HEXATWIST_OK);
  }
  CHECK(allocations == before, "%ld allocations in the real-time calls", allocations - before);
  CHECK(calls > 60, "the success path was exercised (%d)", calls);
}

int main(void) {
  char error[256];
  test_models();
  hexatwist_model* m = hexatwist_model_default(error, sizeof error);
  if (!m) {
    fprintf(stderr, "no default model: %s\n", error);
    return 1;
  }
  test_commands_and_fk(m);
  test_limits(m);
  test_tracking(m);
  test_invalid_arguments(m);
  test_leg_effects();
  test_no_allocation(m);
  hexatwist_model_free(m);
  printf("%d passed, %d failed\n", passed, failed);
  return failed == 0 ? 0 : 1;
}
