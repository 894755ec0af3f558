// SPDX-License-Identifier: BSD-3-Clause
// Tracker-like point logs made from the closed-loop simulation of a platform whose real parameters
// differ from its model by known errors, with the truth beside them: test data for `measure`
// and for an identification, since no real measurement ships with hexatwist (docs/theory.md §12).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "hexatwist/calibration/measurement.hpp"
#include "hexatwist/calibration/parameter_errors.hpp"
#include "hexatwist/calibration/point_log.hpp"

namespace hexatwist {

/// How to make a synthetic log.
struct SynthesisOptions {
  Strategy strategy = Strategy::Compensated;  ///< the commands the platform runs
  ParameterErrors errors;                     ///< the real platform against the nominal model
  /// Standard deviation of the tracker's Gaussian noise on each axis [m]. Default 10 um: the
  /// laser-tracker class of the paper's experiment (a Leica AT960 is specified at 15 um + 6 um/m).
  double noise = 10e-6;
  /// Tracker samples per second [Hz]; the control rate must be a whole multiple of it. 100 Hz
  /// resolves the servo (poles at 10 Hz, bandwidth ~39 Hz) and keeps a log small.
  double rate = 100.0;
  std::uint64_t seed = 1;  ///< seed of the tracker's placement and of the noise
  /// More targets on the platform besides the observation point, measured at every sample after
  /// it, named T2, T3, ... in the log [m, P of the real platform].
  std::vector<Vector3d> extra_targets_P;
  /// Each leg's temperature rise over the run above the real model's reference temperature [K]:
  /// the legs warm along 1 - exp(-t / T) scaled to reach it at the run's end T (a motor's and a
  /// screw's warm-up, whose time constant is of the run's length). It matters where the real
  /// legs expand (ParameterErrors' expansions).
  Vector6d temperature_rise = Vector6d::Zero();
  /// The log gets the machine's temperature at each point (PointLog::temperatures), the legs' mean
  /// [degC], as a sensor on the machine read with each point would give it.
  bool log_temperature = false;
  /// The real platform itself (e.g. the real platform of an earlier synthesis, to drive it with a
  /// corrected configuration's commands: a validation run); when set, `errors` is not used.
  std::optional<ModelSpec> real;
};

/// Throws ParameterError naming the field for options no synthesis can use on `nominal`: noise not
/// finite, < 0 or not below the stroke (limits.length_max - length_min: it would drown every
/// motion); rate not finite and > 0; a lead_error not in (-1, 1); a zero_offset or an
/// observation_offset_P coordinate not finite or not below the stroke in magnitude; a joint offset
/// above kMaxJointError or an axis rotation above kMaxAxisError; a stiffness, play or expansion
/// outside the model's ranges (kinematics/model.hpp; NaN: the nominal one); a temperature_rise not
/// finite or beyond kMaxTemperature - kMinTemperature; more than kMaxTargets targets or one not
/// finite. synthesize runs it; the CLI converts its units and calls it.
void check_synthesis_options(const Model& nominal, const SynthesisOptions& options);

/// The real platform of `options` for the nominal model `nominal`: options.real, or
/// real_model(nominal, options.errors). Throws hexatwist::Error as Model does.
Model real_platform(const Model& nominal, const SynthesisOptions& options);

/// A synthetic log and its truth.
struct SyntheticLog {
  /// The log as a tracker would give it: stamps are the trajectory's time [s]; points [m, T];
  /// lines as in a CSV with one header line (point k on line k + 2).
  PointLog log;
  RigidTransform X_BT;             ///< the tracker frame in the base frame (what registration finds)
  std::vector<Vector3d> true_B;    ///< the real observation point at each point, before transform and noise [m, B]
  std::vector<std::size_t> ticks;  ///< the simulation tick of each point
  std::vector<SimulationSample> simulation;  ///< the closed loop on the nominal model, every tick
};

/// A laser tracker's placement drawn from `seed`: a uniformly random orientation, and its origin
/// 3 to 6 m from the base origin horizontally, 0 to 2 m above it (the platform within range).
RigidTransform random_tracker_frame(std::uint64_t seed);

/// Zero-length offsets drawn independently and uniformly from [-bound, bound] [m] (the same
/// portable generator; another stream of `seed` than the tracker's).
Vector6d random_zero_offsets(double bound, std::uint64_t seed);

/// Simulates `trajectory` on `rig` in closed loop (`simulate`, with options.strategy; the
/// controller and its encoders know only the nominal model) and, at every tracker sample, maps
/// the motors' positions through the real platform: twist-aware forward kinematics of real_model
/// (its joints, leads, offsets and the drives' reference and scale; warm-started) gives the real
/// pose, and there the real observation point and every extra target; the real legs' effects act
/// there too: the static load's deflection at that pose, the temperatures of `temperature_rise`,
/// and the play as lost motion between motor and nut (a dead band followed at every control tick
/// from home, where the homing left each nut on its home_direction's side);
/// it is moved into the tracker frame (random_tracker_frame(seed)) and gets Gaussian noise
/// (portable generator: the same seed gives the same log everywhere). Returns the simulation's
/// status (Ok, or where it stopped in `issue`; forward kinematics failing on the real platform is
/// reported there too). Throws hexatwist::Error for a rate that does not divide the control rate,
/// a noise that is not finite and >= 0, or parameter errors that make no valid model.
[[nodiscard]] Status synthesize(const Rig& rig, const Trajectory& trajectory, const SynthesisOptions& options,
                                SyntheticLog& out, SimulationIssue& issue);

}  // namespace hexatwist
