#include "hexatwist/calibration/parameter_errors.hpp"

namespace hexatwist {

Model real_model(const Model& nominal, const ParameterErrors& errors) {
  ModelSpec spec = nominal.spec();
  for (LegSpec& leg : spec.legs) {
    leg.lead *= 1.0 + errors.lead_error;
    if (errors.flip_twist_sign) leg.thread = leg.thread == ThreadSense::Right ? ThreadSense::Left : ThreadSense::Right;
  }
  spec.observation_P += errors.observation_offset_P;
  return Model(spec);
}

void real_motor_lengths(const Model& nominal, const ParameterErrors& errors, const Vector6d& motor_nominal,
                        Vector6d& motor_real) noexcept {
  const Vector6d& home = nominal.length_home();
  motor_real = home + errors.zero_offset + (1.0 + errors.lead_error) * (motor_nominal - home);
}

}  // namespace hexatwist
