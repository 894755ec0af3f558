// SPDX-License-Identifier: BSD-3-Clause
/* hexatwistkins: LinuxCNC kinematics of a lead-screw Stewart platform with the legs' twist
 * compensated, over the hexatwist C API (include/hexatwist/c/hexatwist.h).
 *
 *   loadrt hexatwistkins [config=FILE.yaml] [strategy=compensated|conventional] [units=mm|inch|m]
 *                        [play=refuse|backlash]
 *
 * World: X Y Z in the machine's length unit, Z the absolute height of the platform frame above the
 * base frame (home: Z = home_height); A B C in degrees, roll, pitch, yaw with R = Rz(C) Ry(B) Rx(A).
 * Joints 0..5: the absolute motor-side lengths of legs 1..6 in the machine's length unit (what the
 * motor encoders measure). Legs that expand (the configuration's leg_effects) get an input pin each,
 * hexatwistkins.leg.N.temperature [degC]. See integrations/linuxcnc/README.md.
 *
 * This unit is C because LinuxCNC's headers are; the kinematics are the library's. Nothing here
 * allocates after rtapi_app_main: the calls made from the servo thread are the C API's real-time
 * calls. */
#include "hal.h"
#include "kinematics.h"
#include "rtapi.h"
#include "rtapi_app.h"
#include "rtapi_math.h"
#include "rtapi_string.h"

#include "hexatwist/c/hexatwist.h"

MODULE_AUTHOR("hexatwist");
MODULE_DESCRIPTION("Twist-compensated kinematics of lead-screw Stewart platforms (hexatwist)");
MODULE_LICENSE("GPL");

static char* config = "";
RTAPI_MP_STRING(config, "hexatwist YAML configuration file (default: the embedded seed platform)");
static char* strategy = "compensated";
RTAPI_MP_STRING(strategy, "motor commands: compensated (default) or conventional (the twist ignored)");
static char* units = "mm";
RTAPI_MP_STRING(units, "machine length unit of X Y Z and of the joints: mm (default), inch or m");
static char* play = "refuse";
RTAPI_MP_STRING(play,
                "legs with play (leg_effects.play): refuse (default) or backlash (LinuxCNC's "
                "[JOINT_n]BACKLASH compensates it; the module leaves it out)");

#define NAME "hexatwistkins"
#define DEG (3.14159265358979323846 / 180.0)

/* What a user watches. Lengths in the machine's unit, angles in degrees. */
struct leg_pins {
  hal_float_t* twist;        /* rod rotation relative to the housing since home [deg] */
  hal_float_t* length_error; /* real minus motor-side length caused by the twist [machine unit] */
  hal_float_t* length;       /* joint-to-joint length [machine unit] */
  hal_float_t* temperature;  /* IN: the leg's temperature [degC] (only for legs that expand) */
};

struct pins {
  struct leg_pins leg[HEXATWIST_LEGS];
  hal_s32_t* ik_status;      /* hexatwist status of the last inverse kinematics (0 ok) */
  hal_u32_t* ik_refused;     /* poses refused by the inverse kinematics since load */
  hal_s32_t* limit_status;   /* kind of the limit nearest to being hit (a hexatwist status code) */
  hal_s32_t* limit_leg;      /* its leg, 1..6; 0 for the platform (Jacobian) limit */
  hal_float_t* limit_margin; /* fraction of that limit's range left: 1 far, 0 on it */
  hal_float_t* condition;    /* condition number of the motor-side Jacobian at the commanded pose */
  hal_s32_t* fk_status;      /* hexatwist status of the last forward kinematics (0 ok) */
  hal_s32_t* fk_iterations;  /* its Newton iterations */
  hal_float_t* fk_residual;  /* its largest length residual [machine unit] */
  hal_bit_t* fk_fail;        /* the last forward kinematics failed */
  hal_u32_t* fk_failures;    /* forward-kinematics failures since load */
  hal_u32_t* fk_recoveries;  /* calls solved only from a fallback start (see README) */
};

static int comp_id = -1;
static hexatwist_model* model = NULL;
static struct pins* pins = NULL;
static hexatwist_strategy command_strategy = HEXATWIST_COMPENSATED;
static double unit_per_m = 1000.0;   /* machine length units per metre */
static double home_height = 0.0;     /* [m] */
static hexatwist_fk_tracker tracker; /* the last forward solution and its assembly mode */
static int expands = 0;              /* the legs expand: the temperature pins exist */

/* The legs' conditions from the pins: the forces the static load's, the temperatures the pins'
 * (the reference without expansion). A pin that is not a number is refused (a failed sensor is not
 * the reference temperature): returns 0 then. The library refuses one outside -60..200 degC. */
static int leg_inputs(hexatwist_leg_inputs* inputs) {
  int i;
  *inputs = hexatwist_leg_inputs_default();
  if (!expands) return 1;
  for (i = 0; i < HEXATWIST_LEGS; ++i) {
    const double t = *pins->leg[i].temperature;
    if (t != t) return 0;
    inputs->temperature[i] = t;
  }
  return 1;
}

/* World pose [machine unit, deg] to a hexatwist pose relative to home [m, rad]. */
static void to_pose(const EmcPose* world, double pose[6]) {
  pose[0] = world->tran.x / unit_per_m;
  pose[1] = world->tran.y / unit_per_m;
  pose[2] = world->tran.z / unit_per_m - home_height;
  pose[3] = world->a * DEG;
  pose[4] = world->b * DEG;
  pose[5] = world->c * DEG;
}

static void to_world(const double pose[6], EmcPose* world) {
  world->tran.x = pose[0] * unit_per_m;
  world->tran.y = pose[1] * unit_per_m;
  world->tran.z = (pose[2] + home_height) * unit_per_m;
  world->a = pose[3] / DEG;
  world->b = pose[4] / DEG;
  world->c = pose[5] / DEG;
  world->u = world->v = world->w = 0.0;
}

int kinematicsInverse(const EmcPose* world, double* joints, const KINEMATICS_INVERSE_FLAGS* iflags,
                      KINEMATICS_FORWARD_FLAGS* fflags) {
  double pose[6];
  hexatwist_command_report report;
  hexatwist_leg_inputs inputs;
  const double* command;
  hexatwist_status status;
  int i;
  (void)iflags;
  if (fflags) *fflags = 0;
  to_pose(world, pose);
  if (!leg_inputs(&inputs)) {
    *pins->ik_status = HEXATWIST_NON_FINITE_INPUT;
    ++*pins->ik_refused;
    return -1;
  }
  status = hexatwist_compute_commands_under(model, pose, &inputs, NULL, &report);
  *pins->ik_status = status;
  *pins->condition = report.condition;
  *pins->limit_status = report.nearest.status;
  *pins->limit_leg = report.nearest.leg;
  *pins->limit_margin = report.nearest_margin;
  if (status != HEXATWIST_OK) {
    /* Outside a limit (or not finite): no joint value is written; LinuxCNC refuses the move. */
    ++*pins->ik_refused;
    return -1;
  }
  command = command_strategy == HEXATWIST_COMPENSATED ? report.compensated : report.conventional;
  for (i = 0; i < HEXATWIST_LEGS; ++i) {
    joints[i] = command[i] * unit_per_m;
    *pins->leg[i].twist = report.twist[i] / DEG;
    *pins->leg[i].length_error = report.length_error[i] * unit_per_m;
    *pins->leg[i].length = report.length[i] * unit_per_m;
  }
  return 0;
}

/* Forward kinematics, designed for a controller that must not stop needlessly. Motion calls it
 * every servo cycle with the previous solution as `world` (home after a failure), and with the
 * commanded joints when it changes modes. The solve starts from the module's own last solution
 * (tracker) and must stay on its assembly mode; if that fails (a jump of the joints, e.g. after a
 * joint-mode move), it starts again from motion's `world`, then from home, each time accepting only
 * the tracker's assembly mode. Only then is a failure returned, with `world` left unchanged. */
int kinematicsForward(const double* joints, EmcPose* world, const KINEMATICS_FORWARD_FLAGS* fflags,
                      KINEMATICS_INVERSE_FLAGS* iflags) {
  double lengths[HEXATWIST_LEGS], guess[6];
  hexatwist_fk_result result;
  hexatwist_fk_tracker fallback;
  hexatwist_leg_inputs inputs;
  hexatwist_status status;
  int i;
  (void)fflags;
  if (iflags) *iflags = 0;
  for (i = 0; i < HEXATWIST_LEGS; ++i) lengths[i] = joints[i] / unit_per_m;
  if (!leg_inputs(&inputs)) {
    *pins->fk_status = HEXATWIST_NON_FINITE_INPUT;
    *pins->fk_fail = 1;
    ++*pins->fk_failures;
    return -1;
  }
  status = hexatwist_forward_kinematics_tracked_under(model, lengths, &inputs, NULL, &tracker, NULL, &result);
  if (status != HEXATWIST_OK && status != HEXATWIST_NON_FINITE_INPUT && status != HEXATWIST_INVALID_ARGUMENT) {
    /* Fallback starts, each accepted only on the tracker's assembly mode. */
    static const double home_pose[6] = {0, 0, 0, 0, 0, 0};
    const double* starts[2];
    to_pose(world, guess);
    starts[0] = guess;
    starts[1] = home_pose;
    for (i = 0; i < 2 && status != HEXATWIST_OK; ++i) {
      if (hexatwist_fk_tracker_set(model, &fallback, starts[i], HEXATWIST_MOTOR) != HEXATWIST_OK) continue;
      if (tracker.valid && fallback.det_sign != tracker.det_sign) continue; /* a start on another mode */
      status = hexatwist_forward_kinematics_tracked_under(model, lengths, &inputs, NULL, &fallback, NULL, &result);
      if (status == HEXATWIST_OK) {
        tracker = fallback;
        ++*pins->fk_recoveries;
      }
    }
  }
  *pins->fk_status = status;
  *pins->fk_iterations = result.iterations;
  *pins->fk_residual = result.residual * unit_per_m;
  *pins->fk_fail = status != HEXATWIST_OK;
  if (status != HEXATWIST_OK) {
    ++*pins->fk_failures;
    return -1;
  }
  to_world(result.pose, world);
  return 0;
}

/* The home pose is LinuxCNC's ([TRAJ] HOME, passed in `world`); the joints follow from it, and the
 * forward solution restarts there on the home assembly mode. */
int kinematicsHome(EmcPose* world, double* joints, KINEMATICS_FORWARD_FLAGS* fflags, KINEMATICS_INVERSE_FLAGS* iflags) {
  double pose[6];
  *fflags = 0;
  *iflags = 0;
  to_pose(world, pose);
  if (hexatwist_fk_tracker_set(model, &tracker, pose, HEXATWIST_MOTOR) != HEXATWIST_OK)
    hexatwist_fk_tracker_reset(&tracker);
  return kinematicsInverse(world, joints, iflags, fflags);
}

KINEMATICS_TYPE kinematicsType(void) { return KINEMATICS_BOTH; }

KINS_NOT_SWITCHABLE
EXPORT_SYMBOL(kinematicsType);
EXPORT_SYMBOL(kinematicsForward);
EXPORT_SYMBOL(kinematicsInverse);
EXPORT_SYMBOL(kinematicsHome);

/* The temperature pins exist only for legs that expand (a `net` to one of a configuration without
 * expansion fails the HAL file, rather than a sensor changing nothing); they start at the reference
 * temperature, so that an unconnected pin leaves the commands those without expansion. */
static int export_pins(double reference_temperature) {
  int i, r = 0;
  pins = hal_malloc(sizeof *pins);
  if (!pins) return -1;
  for (i = 0; i < HEXATWIST_LEGS && r == 0; ++i) {
    r |= hal_pin_float_newf(HAL_OUT, &pins->leg[i].twist, comp_id, NAME ".leg.%d.twist", i + 1);
    r |= hal_pin_float_newf(HAL_OUT, &pins->leg[i].length_error, comp_id, NAME ".leg.%d.length-error", i + 1);
    r |= hal_pin_float_newf(HAL_OUT, &pins->leg[i].length, comp_id, NAME ".leg.%d.length", i + 1);
    pins->leg[i].temperature = NULL;
    if (expands) {
      r |= hal_pin_float_newf(HAL_IN, &pins->leg[i].temperature, comp_id, NAME ".leg.%d.temperature", i + 1);
      if (r == 0) *pins->leg[i].temperature = reference_temperature;
    }
  }
  r |= hal_pin_s32_newf(HAL_OUT, &pins->ik_status, comp_id, NAME ".ik-status");
  r |= hal_pin_u32_newf(HAL_OUT, &pins->ik_refused, comp_id, NAME ".ik-refused");
  r |= hal_pin_s32_newf(HAL_OUT, &pins->limit_status, comp_id, NAME ".limit-nearest");
  r |= hal_pin_s32_newf(HAL_OUT, &pins->limit_leg, comp_id, NAME ".limit-leg");
  r |= hal_pin_float_newf(HAL_OUT, &pins->limit_margin, comp_id, NAME ".limit-margin");
  r |= hal_pin_float_newf(HAL_OUT, &pins->condition, comp_id, NAME ".condition");
  r |= hal_pin_s32_newf(HAL_OUT, &pins->fk_status, comp_id, NAME ".fk-status");
  r |= hal_pin_s32_newf(HAL_OUT, &pins->fk_iterations, comp_id, NAME ".fk-iterations");
  r |= hal_pin_float_newf(HAL_OUT, &pins->fk_residual, comp_id, NAME ".fk-residual");
  r |= hal_pin_bit_newf(HAL_OUT, &pins->fk_fail, comp_id, NAME ".fk-fail");
  r |= hal_pin_u32_newf(HAL_OUT, &pins->fk_failures, comp_id, NAME ".fk-failures");
  r |= hal_pin_u32_newf(HAL_OUT, &pins->fk_recoveries, comp_id, NAME ".fk-recoveries");
  return r;
}

/* Reads the module parameters; on a bad one, says which and fails the load. */
static int read_parameters(void) {
  if (strcmp(strategy, "compensated") == 0) {
    command_strategy = HEXATWIST_COMPENSATED;
  } else if (strcmp(strategy, "conventional") == 0) {
    command_strategy = HEXATWIST_CONVENTIONAL;
  } else {
    rtapi_print_msg(RTAPI_MSG_ERR, NAME ": strategy=%s: expected compensated or conventional\n", strategy);
    return -1;
  }
  if (strcmp(play, "refuse") != 0 && strcmp(play, "backlash") != 0) {
    rtapi_print_msg(RTAPI_MSG_ERR, NAME ": play=%s: expected refuse or backlash\n", play);
    return -1;
  }
  if (strcmp(units, "mm") == 0) {
    unit_per_m = 1000.0;
  } else if (strcmp(units, "inch") == 0) {
    unit_per_m = 1.0 / 0.0254;
  } else if (strcmp(units, "m") == 0) {
    unit_per_m = 1.0;
  } else {
    rtapi_print_msg(RTAPI_MSG_ERR, NAME ": units=%s: expected mm, inch or m\n", units);
    return -1;
  }
  return 0;
}

int rtapi_app_main(void) {
  char error[512];
  double reference_temperature = 0.0;
  comp_id = hal_init(NAME);
  if (comp_id < 0) return comp_id;
  if (read_parameters() != 0) {
    hal_exit(comp_id);
    return -EINVAL;
  }
  model = config[0] != '\0' ? hexatwist_model_from_file(config, error, sizeof error)
                            : hexatwist_model_default(error, sizeof error);
  if (!model) {
    rtapi_print_msg(RTAPI_MSG_ERR, NAME ": %s\n", error);
    hal_exit(comp_id);
    return -EINVAL;
  }
  if (hexatwist_model_play(model, NULL)) {
    /* The module keeps no direction of motion: LinuxCNC's own backlash compensation does, with
     * play=backlash (and each joint's [JOINT_n]BACKLASH, which hexatwist linuxcnc writes). */
    hexatwist_model* rigid =
        strcmp(play, "backlash") == 0 ? hexatwist_model_without_play(model, error, sizeof error) : NULL;
    if (!rigid)
      rtapi_print_msg(RTAPI_MSG_ERR,
                      NAME
                      ": %s: its legs have play (leg_effects.play): load with play=backlash and give it to "
                      "LinuxCNC as each joint's [JOINT_n]BACKLASH (hexatwist linuxcnc writes both)\n",
                      config[0] != '\0' ? config : "the configuration");
    hexatwist_model_free(model);
    model = rigid;
    if (!model) {
      hal_exit(comp_id);
      return -EINVAL;
    }
  }
  home_height = hexatwist_model_home_height(model);
  hexatwist_fk_tracker_reset(&tracker);
  expands = hexatwist_model_expands(model, &reference_temperature);
  if (export_pins(reference_temperature) != 0) {
    rtapi_print_msg(RTAPI_MSG_ERR, NAME ": cannot export the HAL pins\n");
    hexatwist_model_free(model);
    model = NULL;
    hal_exit(comp_id);
    return -ENOMEM;
  }
  rtapi_print_msg(RTAPI_MSG_INFO, NAME ": %s, %s commands, %s%s\n", hexatwist_model_name(model), strategy, units,
                  expands ? ", leg temperatures from hexatwistkins.leg.N.temperature" : "");
  hal_ready(comp_id);
  return 0;
}

void rtapi_app_exit(void) {
  hexatwist_model_free(model);
  model = NULL;
  hal_exit(comp_id);
}
