// SPDX-License-Identifier: BSD-3-Clause
/* hexatwist C API: twist-aware kinematics of lead-screw Stewart platforms, for C and for any
 * language's foreign-function interface (C99).
 *
 * One opaque, immutable model (built from a YAML file, YAML text or the embedded seed platform)
 * and free functions that write into caller-owned structs and return a status code. Every
 * function except the three model constructors is real-time safe: it never allocates, never
 * blocks and never lets a C++ exception cross this boundary. A model may be shared by any number
 * of threads; a `hexatwist_fk_tracker` belongs to one caller.
 *
 * Units and frames (docs/notation.md): SI everywhere. A pose is `{x, y, z, roll, pitch, yaw}`
 * [m, m, m, rad, rad, rad] of the platform relative to home, in the base frame B, with
 * R = Rz(yaw) Ry(pitch) Rx(roll) (paper Eq. 3). Leg quantities are arrays of six, leg 1 first.
 * Motor-side lengths are what the motor encoder sees: the joint-to-joint length minus the
 * twist's contribution lead * dtheta / 2pi (paper Eq. 10) minus the leg's length offset. */
#ifndef HEXATWIST_C_HEXATWIST_H
#define HEXATWIST_C_HEXATWIST_H

#include <stddef.h>

#ifdef __cplusplus
extern "C" {
#endif

/** Number of legs. */
#define HEXATWIST_LEGS 6

/** Outcome of a call; 0 is the only success. The values are those of hexatwist::Status. */
typedef enum hexatwist_status {
  HEXATWIST_OK = 0,
  HEXATWIST_NON_FINITE_INPUT = 1,       /**< a pose, length or guess holds NaN or inf */
  HEXATWIST_STROKE_BELOW_MIN = 2,       /**< a leg is shorter than its minimum length */
  HEXATWIST_STROKE_ABOVE_MAX = 3,       /**< a leg is longer than its maximum length */
  HEXATWIST_BEND_BASE = 4,              /**< a base U-joint bends past its limit */
  HEXATWIST_BEND_PLATFORM = 5,          /**< a platform U-joint bends past its limit */
  HEXATWIST_SINGULAR_BASE = 6,          /**< a leg is too close to its base U-joint's fixed axis */
  HEXATWIST_SINGULAR_PLATFORM = 7,      /**< a leg is too close to its platform U-joint's fixed axis */
  HEXATWIST_NO_CONVERGENCE = 8,         /**< forward kinematics did not reach its tolerance */
  HEXATWIST_SINGULAR_JACOBIAN = 9,      /**< forward kinematics met a singular Jacobian */
  HEXATWIST_PLATFORM_SINGULARITY = 17,  /**< the pose is too close to a platform (Jacobian) singularity */
  HEXATWIST_ASSEMBLY_MODE_CHANGED = 18, /**< forward kinematics would land on another assembly mode */
  HEXATWIST_INVALID_ARGUMENT = 100,     /**< a null pointer, an unknown enum value, an option outside its
                                             documented range (hexatwist_fk_options) or a leg length <= 0 */
  HEXATWIST_STATUS_MAX_ENUM = 0x7FFFFFFF
} hexatwist_status;

/* Each enum ends with a *_MAX_ENUM member so that it spans every non-negative int: a value from
 * another language that is no enumerator is then still a value of the type, and the call answers
 * HEXATWIST_INVALID_ARGUMENT instead of reading an invalid enum. */

/** How motor-side commands are formed. */
typedef enum hexatwist_strategy {
  HEXATWIST_CONVENTIONAL = 0, /**< joint-to-joint length minus offset; the twist ignored */
  HEXATWIST_COMPENSATED = 1,  /**< the twist's length change subtracted (paper Eq. 12) */
  HEXATWIST_STRATEGY_MAX_ENUM = 0x7FFFFFFF
} hexatwist_strategy;

/** What a set of leg lengths means. */
typedef enum hexatwist_length_kind {
  HEXATWIST_GEOMETRIC = 0, /**< joint-to-joint lengths [m] */
  HEXATWIST_MOTOR = 1,     /**< motor-side lengths [m] (twist and offsets included) */
  HEXATWIST_LENGTH_KIND_MAX_ENUM = 0x7FFFFFFF
} hexatwist_length_kind;

/** The validated platform model (opaque, immutable). */
typedef struct hexatwist_model hexatwist_model;

/** Which limit a pose broke. */
typedef struct hexatwist_limit {
  hexatwist_status status; /**< HEXATWIST_OK, or the limit broken */
  int leg;                 /**< offending leg, 1-based; 0 for a limit of the whole platform or none */
  double value;            /**< the offending quantity [m, rad, or the condition number] */
  double bound;            /**< the limit it crossed [same unit] */
} hexatwist_limit;

/** Everything about one commanded pose. */
typedef struct hexatwist_command_report {
  double length[HEXATWIST_LEGS];       /**< joint-to-joint leg lengths, Eq. (4) [m] */
  double twist[HEXATWIST_LEGS];        /**< rod rotation relative to the housing since home [rad] */
  double length_error[HEXATWIST_LEGS]; /**< real minus motor-side length from the twist, Eq. (10) [m] */
  double conventional[HEXATWIST_LEGS]; /**< motor-side command, twist ignored [m] */
  double compensated[HEXATWIST_LEGS];  /**< motor-side command, Eq. (12) [m] */
  double condition;                    /**< condition number of the motor-side Jacobian [-] */
  hexatwist_limit limit;               /**< the first limit broken, if any */
  hexatwist_limit nearest;             /**< the limit nearest to being hit: its status names the kind,
                                            `value` and `bound` as in `limit` */
  double nearest_margin;               /**< how far from it, as the fraction of its range left:
                                            1 far away, 0 on the limit, negative past it [-] */
} hexatwist_command_report;

/** The legs' conditions for a model with leg effects (docs/theory/kinematics.md §4b); start from
 * hexatwist_leg_inputs_default(). */
typedef struct hexatwist_leg_inputs {
  double force[HEXATWIST_LEGS];       /**< axial force, tension positive [N]; NaN = the static load's */
  double temperature[HEXATWIST_LEGS]; /**< temperature [degC]; NaN = the model's reference */
} hexatwist_leg_inputs;

/** Each leg's direction of its last motion, for its play (caller-owned, one per controller; start it
 * with hexatwist_play_start after homing). */
typedef struct hexatwist_play_state {
  int started;                      /**< 0: each leg approached straight from home */
  double direction[HEXATWIST_LEGS]; /**< +1 lengthening, -1 shortening */
  double last[HEXATWIST_LEGS];      /**< the last travel before its play term [m] */
} hexatwist_play_state;

/** Forward-kinematics settings; start from hexatwist_fk_default_options(). A value outside its range
 * (NaN included) makes the call return HEXATWIST_INVALID_ARGUMENT, as the library, the CLI and Python
 * refuse it. */
typedef struct hexatwist_fk_options {
  int max_iterations;          /**< Newton iterations before HEXATWIST_NO_CONVERGENCE, 1 to 1000 */
  double tolerance;            /**< largest |length residual| accepted [m], > 0 and at most 1e-6 */
  double max_step_translation; /**< largest translation of one Newton step [m], > 0 and at most 10 */
  double max_step_rotation;    /**< largest rotation vector |dw| of one Newton step [rad], > 0 and at most pi */
} hexatwist_fk_options;

/** Outcome of forward kinematics. */
typedef struct hexatwist_fk_result {
  double pose[6];   /**< the solution (the best iterate when not converged) [m, rad] */
  int iterations;   /**< Newton iterations taken */
  double residual;  /**< largest |length residual| at `pose` [m] */
  double condition; /**< condition number of the Jacobian at `pose` [-] */
} hexatwist_fk_result;

/** Forward kinematics along a motion: the last solution and its assembly mode. Caller-owned;
 * zero-initialise it (or call hexatwist_fk_tracker_reset) to start from home. */
typedef struct hexatwist_fk_tracker {
  double t[3];     /**< displacement of the last solution from home [m, B] */
  double R[9];     /**< its orientation, row-major [-] */
  double det_sign; /**< sign of the Jacobian's determinant there: the assembly mode */
  int valid;       /**< 0: no solution yet (home is the start and the reference mode) */
} hexatwist_fk_tracker;

/* ---- Model (not real-time: these allocate and read files) ---------------------------------- */

/** Model from a hexatwist YAML configuration file. NULL on failure, with a one-line message
 * naming the file, line, field or leg written to `error` (truncated to `error_size`; may be NULL). */
hexatwist_model* hexatwist_model_from_file(const char* path, char* error, size_t error_size);

/** Model from YAML text; `source` names it in error messages (may be NULL). */
hexatwist_model* hexatwist_model_from_yaml(const char* yaml_text, const char* source, char* error, size_t error_size);

/** The embedded seed platform (configs/seed.yaml: the paper's platform, lead 10 mm). */
hexatwist_model* hexatwist_model_default(char* error, size_t error_size);

/** Frees a model (NULL is allowed). */
void hexatwist_model_free(hexatwist_model* model);

/** The model's name (valid as long as the model). */
const char* hexatwist_model_name(const hexatwist_model* model);

/** Height of the platform frame's origin above the base frame's origin at home [m]. */
double hexatwist_model_home_height(const hexatwist_model* model);

/** Leg lengths at home: joint-to-joint and motor-side [m] (either pointer may be NULL). */
void hexatwist_model_home_lengths(const hexatwist_model* model, double geometric[HEXATWIST_LEGS],
                                  double motor[HEXATWIST_LEGS]);

/** Motor-side lengths the drives read at their reference, the homing position (LinuxCNC's joint
 * HOME; the configuration's home_commands, by default the motor-side lengths at home) [m]. */
void hexatwist_model_home_commands(const hexatwist_model* model, double motor[HEXATWIST_LEGS]);

/** Stroke limits of the legs, shortest and longest [m] (either pointer may be NULL). */
void hexatwist_model_stroke(const hexatwist_model* model, double* length_min, double* length_max);

/** Each leg's play [m] (its `leg_effects` block; 0 without), written to `play`; returns non-zero if a
 * leg has play (docs/theory/kinematics.md §4b). */
int hexatwist_model_play(const hexatwist_model* model, double play[HEXATWIST_LEGS]);

/** A copy of `model` whose legs have no play, for a controller that compensates the play itself
 * (LinuxCNC's [JOINT_n]BACKLASH, which follows each joint's direction): its commands and forward
 * kinematics are those of hexatwist_model_play's legs without it. NULL on failure (a NULL model),
 * with a one-line message in `error`. Not real-time: it allocates. */
hexatwist_model* hexatwist_model_without_play(const hexatwist_model* model, char* error, size_t error_size);

/** Non-zero if the model's legs expand with their temperature (`leg_effects`: length_expansion or
 * lead_expansion); its reference temperature [degC] written to `reference_temperature` (may be
 * NULL), the temperature at which the commands are those without expansion. */
int hexatwist_model_expands(const hexatwist_model* model, double* reference_temperature);

/* ---- Real-time calls ----------------------------------------------------------------------- */

/** Motor-side commands for `pose` [m, rad] with `strategy`, every limit checked. `command` [m]
 * is written only on HEXATWIST_OK; otherwise `limit` (may be NULL) names the leg and limit. */
hexatwist_status hexatwist_motor_commands(const hexatwist_model* model, const double pose[6],
                                          hexatwist_strategy strategy, double command[HEXATWIST_LEGS],
                                          hexatwist_limit* limit);

/** Default leg conditions: every force and temperature NaN (the static load, the reference). */
hexatwist_leg_inputs hexatwist_leg_inputs_default(void);

/** Starts `play` where homing leaves the legs: at the drives' reference, each leg's direction its
 * home_direction. */
void hexatwist_play_start(const hexatwist_model* model, hexatwist_play_state* play);

/** hexatwist_motor_commands under the conditions `inputs` (NULL: the defaults) with the play's
 * directions from `play` (NULL: each leg approached from home), moved on to this command on
 * HEXATWIST_OK. For a model without leg effects, or the conventional strategy, the same command as
 * hexatwist_motor_commands. HEXATWIST_NON_FINITE_INPUT for an infinite force or temperature. */
hexatwist_status hexatwist_motor_commands_under(const hexatwist_model* model, const double pose[6],
                                                hexatwist_strategy strategy, const hexatwist_leg_inputs* inputs,
                                                hexatwist_play_state* play, double command[HEXATWIST_LEGS],
                                                hexatwist_limit* limit);

/** Lengths, twist, length error, both commands and the limit check for `pose` (paper Eq. 1-12).
 * On a status other than HEXATWIST_OK the commands must not be sent. */
hexatwist_status hexatwist_compute_commands(const hexatwist_model* model, const double pose[6],
                                            hexatwist_command_report* report);

/** hexatwist_compute_commands under the conditions `inputs` (NULL: the defaults) with the play's
 * directions from `play` (NULL: each leg approached from home; not moved on, as
 * hexatwist_motor_commands_under does). The compensated command includes the legs' effects where the
 * model has them. HEXATWIST_INVALID_ARGUMENT for a temperature outside -60 to 200 degC,
 * HEXATWIST_NON_FINITE_INPUT for an infinite force or temperature. */
hexatwist_status hexatwist_compute_commands_under(const hexatwist_model* model, const double pose[6],
                                                  const hexatwist_leg_inputs* inputs, const hexatwist_play_state* play,
                                                  hexatwist_command_report* report);

/** Twist of each leg relative to home [rad] at `pose` (limits not checked). */
hexatwist_status hexatwist_twist(const hexatwist_model* model, const double pose[6], double twist[HEXATWIST_LEGS]);

/** Default forward-kinematics settings (the library's). */
hexatwist_fk_options hexatwist_fk_default_options(void);

/** Forward kinematics from `lengths` [m] of `kind`, starting at `guess` [m, rad] (NULL: home).
 * Refuses to land on another assembly mode than the guess's. `options` may be NULL. */
hexatwist_status hexatwist_forward_kinematics(const hexatwist_model* model, const double lengths[HEXATWIST_LEGS],
                                              hexatwist_length_kind kind, const double guess[6],
                                              const hexatwist_fk_options* options, hexatwist_fk_result* result);

/** Forward kinematics along a motion: starts at the tracker's last solution (home at first) and
 * succeeds only on the tracker's assembly mode; updates the tracker on HEXATWIST_OK only. */
hexatwist_status hexatwist_forward_kinematics_tracked(const hexatwist_model* model,
                                                      const double lengths[HEXATWIST_LEGS], hexatwist_length_kind kind,
                                                      hexatwist_fk_tracker* tracker,
                                                      const hexatwist_fk_options* options, hexatwist_fk_result* result);

/** hexatwist_forward_kinematics_tracked of the drives' motor-side lengths `motor` [m] under the
 * conditions `inputs` (NULL: the defaults) with the play's directions from `play` (NULL or not
 * started: each leg approached from home): where the real legs, deflected, warm and with their
 * play, have these lengths (docs/theory/kinematics.md §4b). The same acceptance as the call above;
 * statuses as hexatwist_compute_commands_under for the inputs. */
hexatwist_status hexatwist_forward_kinematics_tracked_under(
    const hexatwist_model* model, const double motor[HEXATWIST_LEGS], const hexatwist_leg_inputs* inputs,
    const hexatwist_play_state* play, hexatwist_fk_tracker* tracker, const hexatwist_fk_options* options,
    hexatwist_fk_result* result);

/** Forgets the tracker's solution: the next tracked call starts from home. */
void hexatwist_fk_tracker_reset(hexatwist_fk_tracker* tracker);

/** Sets the tracker to a known pose [m, rad] (e.g. after homing), with that pose's assembly mode
 * for lengths of `kind`; the tracker is unchanged on failure. */
hexatwist_status hexatwist_fk_tracker_set(const hexatwist_model* model, hexatwist_fk_tracker* tracker,
                                          const double pose[6], hexatwist_length_kind kind);

/** The library's version, "major.minor.patch" (hexatwist/version.hpp). */
const char* hexatwist_version(void);

/** Stable snake_case name of a status ("stroke_above_max"); "unknown" for other values. */
const char* hexatwist_status_name(hexatwist_status status);

/** One-sentence description of a status. */
const char* hexatwist_status_describe(hexatwist_status status);

/** Non-zero for the statuses that mean "this pose is outside a limit". */
int hexatwist_status_is_limit(hexatwist_status status);

#ifdef __cplusplus
}
#endif

#endif /* HEXATWIST_C_HEXATWIST_H */
