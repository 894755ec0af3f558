// SPDX-License-Identifier: BSD-3-Clause
// Identification from tracker logs (theory §13). examples/tracker_Rz.csv, the Rz test after the
// calibration moves, cannot separate the observation point's height from the tracker's: identify
// answers not_identifiable and names the combination (a status, not an exception). A run of 40
// random stations, every coordinate at once (examples/tracker_stations.csv, made by `hexatwist synth
// --stations 40 --station-seed 4 --offsets-mm 0.33 --seed 3 --rate 10`), determines the legs'
// zero offsets. The twin of examples/python/06_identify.py, which also compares with the truth.
//
//   example_06_identify [EXAMPLES_DIR]      (default: this source folder, from any working directory)
#include <hexatwist/hexatwist.hpp>

#include <cstdio>
#include <string>

namespace {

using namespace hexatwist;

// The log's points at rest under a commanded run, identified with the basic model (the joints as
// configured: lead, zero offsets, observation point, tracker frame); prints what it found.
void identify_log(const Model& model, const std::string& path, const std::string& name, const Trajectory& run) {
  const PointLog log = parse_point_log(read_text_file(path, "point log", kMaxDataBytes), path, PointLogFormat{});
  const ObservationSet set = observations_at_rest(model, timed_poses(run), log, TimeAlignment{}, Strategy::Compensated,
                                                  0.25);  // points while the commanded pose was still for 0.25 s
  std::printf("%s: %zu points, %zu at rest at %zu stations\n", name.c_str(), log.stamps.size(), set.observations.size(),
              set.poses);
  IdentificationOptions options;
  options.model = CalibrationModel::Basic;
  Identification id;
  const Status s = identify(model, set.observations, id, options);
  if (s != Status::Ok) {
    std::printf("identify: %s: %s\n", to_string(s).data(), id.reason.c_str());
    return;
  }
  std::printf("identify: ok; rms residual %.4f mm -> %.4f mm, tracker noise %.4f mm\n", 1e3 * id.rms_before,
              1e3 * id.rms_after, 1e3 * id.tracker_noise);
  for (int k = 0; k < id.parameters.size(); ++k)
    if (id.parameters.name(k).rfind("offset", 0) == 0)
      std::printf("  %s: %+.4f mm +- %.4f mm\n", id.parameters.name(k).c_str(), 1e3 * id.estimate[k], 1e3 * id.sd[k]);
}

void identify_both(const std::string& dir) {
  const Config config = default_config();
  const Model& model = config.rig.model();
  const double dt = config.rig.control_period();

  double calibration_end = 0.0;  // the measured test: the calibration moves, then the study's Rz
  const Trajectory rz =
      measured_test_trajectory(config.study, study_test(config.study, "Rz"), CalibrationSpec{}, dt, calibration_end);
  identify_log(model, dir + "/tracker_Rz.csv", "tracker_Rz.csv", rz);

  StationsSpec stations;  // the synth's run: 40 stations of seed 4
  stations.count = 40;
  stations.seed = 4;
  identify_log(model, dir + "/tracker_stations.csv", "tracker_stations.csv",
               stations_trajectory(model, Strategy::Compensated, stations, dt));
}

}  // namespace

int main(int argc, char** argv) {
  try {
    identify_both(argc > 1 ? argv[1] : HEXATWIST_EXAMPLES_DIR);
    return 0;
  } catch (const Error& e) {  // a missing or unreadable log: say which, as the CLI does
    std::fprintf(stderr, "example_06_identify: %s\n", e.what());
    return 1;
  }
}
