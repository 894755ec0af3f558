#include "hexatwist/design/tolerance_calibration.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "design/design_support.hpp"
#include "hexatwist/design/required_workspace.hpp"
#include "hexatwist/error.hpp"

namespace hexatwist {
namespace {

std::vector<Pose> workspace(int random) { return test::required_poses(random); }

TrackerCalibration forty_stations() {
  TrackerCalibration c;
  StationsSpec st;
  st.count = 40;
  c.stations = random_station_plan(test::seed_model(), st);
  return c;
}

// The calibrated study and its linear model (10 platforms, 224 poses: about 0.5 s).
struct Study {
  std::vector<Pose> poses = workspace(200);
  ToleranceOptions options;
  ToleranceLinear linear;
  ToleranceChunk chunk;
};

void run_calibrated(const TrackerCalibration& c, std::size_t platforms, Study& s) {
  ASSERT_EQ(calibrated_linear(test::seed_model(), s.poses, s.options, c, s.linear), Status::Ok);
  s.options.calibration = tracker_calibration_step(c);
  ASSERT_EQ(tolerance_chunk(test::seed_model(), s.poses, s.options, 0, platforms, s.chunk, &s.linear), Status::Ok);
}

TEST(ToleranceCalibration, TheStationPlanRunsFromHomeToHome) {
  const TrackerCalibration c = forty_stations();
  ASSERT_EQ(c.stations.size(), 42u);
  EXPECT_EQ(c.stations.front(), Vector6d::Zero());
  EXPECT_EQ(c.stations.back(), Vector6d::Zero());
  for (std::size_t k = 1; k + 1 < c.stations.size(); ++k) EXPECT_GT(c.stations[k].norm(), 0.0);
}

TEST(ToleranceCalibration, TheTrackerSeesTheRealPlatformInItsOwnFrame) {
  // Noise drawn once and replayed: the observations minus the noise, mapped by the sample's tracker
  // frame, are the real platform's point where the nominal commands put it.
  const Model& seed = test::seed_model();
  const Model real(real_platform(seed, sample_errors(seed, ToleranceSigmas{}, 1, 4)));
  TrackerCalibration c = forty_stations();
  c.points = 3;
  std::vector<Observation> obs;
  ASSERT_EQ(tracker_observations(seed, real, c, 4, obs), Status::Ok);
  ASSERT_EQ(obs.size(), 3 * c.stations.size());
  const std::vector<Vector3d> noise = tracker_noise(c, 4);
  const RigidTransform X_BT = sample_tracker_frame(c, 4);
  double scatter = 0.0;
  for (std::size_t k = 0; k < obs.size(); ++k) {
    const Pose pose = Pose::from_vector(c.stations[k / 3]);
    Vector6d m;
    LimitReport r;
    ASSERT_EQ(motor_commands(seed, pose, Strategy::Compensated, m, r), Status::Ok);
    EXPECT_EQ(obs[k].motor, m);
    FkResult fk;
    ASSERT_EQ(forward_kinematics(real, m, LengthKind::Motor, placement_from_pose(pose), fk), Status::Ok);
    const Vector3d A_B = platform_point_B(real, fk.placement, real.spec().observation_P);
    EXPECT_LT((apply(X_BT, obs[k].p_T - noise[k]) - A_B).norm(), 1e-12);
    scatter += noise[k].squaredNorm();
  }
  // The noise has the standard deviation asked (3 x 126 draws: within 15 %).
  EXPECT_NEAR(std::sqrt(scatter / (3.0 * static_cast<double>(obs.size()))), c.noise, 0.15 * c.noise);
}

TEST(ToleranceCalibration, ANoiselessCalibrationOfIdentifiableErrorsLeavesNone) {
  // Without axis errors every manufacturing error is a parameter identify fits: with 1 nm of
  // tracker noise the calibrated machine is exact to it (measured 9 nm max; before: ~250 um).
  Study s;
  s.options.sigmas.base_axis = s.options.sigmas.platform_axis = 0.0;
  s.options.linear_worst = false;
  TrackerCalibration c = forty_stations();
  c.noise = 1e-9;
  s.options.calibration = tracker_calibration_step(c);
  ASSERT_EQ(tolerance_chunk(test::seed_model(), s.poses, s.options, 0, 4, s.chunk), Status::Ok);
  for (std::size_t k = 0; k < s.chunk.size(); ++k) {
    EXPECT_EQ(s.chunk.failures[k], 0u);
    EXPECT_LT(s.chunk.max_point[k], 1e-7) << k;
  }
}

TEST(ToleranceCalibration, LinearisedAndMonteCarloAnswersAgree) {
  // Measured (seed platform, default sigmas, 40 stations, 10 um noise, 50 points a station):
  // per platform worst point error MC vs the linear model with the same errors within 0.4 %; pooled
  // median 0.99 of the covariance answer's, p95 0.93 (10 platforms).
  Study s;
  run_calibrated(forty_stations(), 10, s);
  const ToleranceSummary sm = summarize_tolerance(s.chunk, s.poses.size(), &s.linear, 0);
  EXPECT_EQ(sm.failures, 0u);
  for (std::size_t k = 0; k < s.chunk.size(); ++k)
    EXPECT_NEAR(s.chunk.max_point_linear[k] / s.chunk.max_point[k], 1.0, 0.04) << "platform " << k;
  EXPECT_NEAR(sm.point.median / sm.point_linear.median, 1.0, 0.1);
  EXPECT_NEAR(sm.point.p95 / sm.point_linear.p95, 1.0, 0.25);
  // The same in the joints' least-squares frames (measured: median ratio 0.94).
  Study j;
  TrackerCalibration c = forty_stations();
  c.frames = CalibratedFrames::Joints;
  run_calibrated(c, 10, j);
  const ToleranceSummary sj = summarize_tolerance(j.chunk, j.poses.size(), &j.linear, 0);
  for (std::size_t k = 0; k < j.chunk.size(); ++k)
    EXPECT_NEAR(j.chunk.max_point_linear[k] / j.chunk.max_point[k], 1.0, 0.1) << "platform " << k;
  EXPECT_NEAR(sj.point.median / sj.point_linear.median, 1.0, 0.25);
}

TEST(ToleranceCalibration, CalibrationReducesThePointError) {
  // Measured: point error median 1.79 um after, against 0.22 mm with the nominal controller (joint
  // sigma 50 um, lead 50 ppm, offsets 0.1 mm, axes 0.1 deg): a factor of 122; the worst 23.
  Study after;
  run_calibrated(forty_stations(), 10, after);
  Study before;
  ASSERT_EQ(tolerance_linear(test::seed_model(), before.poses, before.options.sigmas, before.linear, 0), Status::Ok);
  ASSERT_EQ(tolerance_chunk(test::seed_model(), before.poses, before.options, 0, 10, before.chunk, &before.linear),
            Status::Ok);
  const ToleranceSummary a = summarize_tolerance(after.chunk, after.poses.size(), &after.linear, 0);
  const ToleranceSummary b = summarize_tolerance(before.chunk, before.poses.size(), &before.linear, 0);
  EXPECT_GT(b.point.median / a.point.median, 50.0);
  EXPECT_GT(b.worst_point.max / a.worst_point.max, 5.0);
  // More tracker noise, less accuracy: the covariance answer grows with it (linear: x10 exactly
  // for the noise part).
  TrackerCalibration noisy = forty_stations();
  noisy.noise = 100e-6;
  ToleranceLinear l;
  ASSERT_EQ(calibrated_linear(test::seed_model(), after.poses, after.options, noisy, l), Status::Ok);
  ToleranceSummary ln;
  linear_quantiles(l, ln, 0);
  EXPECT_GT(ln.point_linear.median, 3.0 * a.point_linear.median);
}

TEST(ToleranceCalibration, TheStudyIsDeterministicGivenItsSeed) {
  Study one, two;
  one.options.threads = 1;
  two.options.threads = 2;
  const TrackerCalibration c = forty_stations();
  ASSERT_EQ(calibrated_linear(test::seed_model(), one.poses, one.options, c, one.linear), Status::Ok);
  one.options.calibration = two.options.calibration = tracker_calibration_step(c);
  ASSERT_EQ(tolerance_chunk(test::seed_model(), one.poses, one.options, 0, 4, one.chunk, &one.linear), Status::Ok);
  // Two chunks [0,2) + [2,4) on two threads: bit for bit the one chunk.
  ToleranceChunk second;
  ASSERT_EQ(tolerance_chunk(test::seed_model(), two.poses, two.options, 0, 2, two.chunk, &one.linear), Status::Ok);
  ASSERT_EQ(tolerance_chunk(test::seed_model(), two.poses, two.options, 2, 2, second, &one.linear), Status::Ok);
  append_chunk(two.chunk, second);
  ASSERT_EQ(one.chunk.size(), two.chunk.size());
  for (std::size_t k = 0; k < one.chunk.size(); ++k) {
    EXPECT_EQ(std::memcmp(&one.chunk.max_point[k], &two.chunk.max_point[k], sizeof(double)), 0);
    EXPECT_EQ(std::memcmp(&one.chunk.max_point_linear[k], &two.chunk.max_point_linear[k], sizeof(double)), 0);
  }
  EXPECT_EQ(one.chunk.point.counts, two.chunk.point.counts);
  // Another tracker seed: other noise, other errors.
  TrackerCalibration other = c;
  other.seed = 2;
  two.options.calibration = tracker_calibration_step(other);
  ASSERT_EQ(tolerance_chunk(test::seed_model(), two.poses, two.options, 0, 1, second, &one.linear), Status::Ok);
  EXPECT_NE(second.max_point[0], one.chunk.max_point[0]);
}

TEST(ToleranceCalibration, HeldPosesOfARunAreItsStations) {
  TimedPoses run;
  const auto at = [&](double t, double x) {
    run.t.push_back(t);
    run.poses.push_back(Pose::from_vector((Vector6d() << x, 0, 0, 0, 0, 0).finished()));
  };
  at(0, 0), at(1, 0), at(2, 0.01), at(3, 0.02), at(4, 0.02), at(5, 0.02), at(6, 0.01), at(7, 0), at(8, 0);
  const std::vector<Vector6d> s = run_stations(run);
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s[0][0], 0.0);
  EXPECT_EQ(s[1][0], 0.02);
  EXPECT_EQ(s[2][0], 0.0);
}

TEST(ToleranceCalibration, BadInputsAreRefusedNamingTheField) {
  const auto refused = [](const TrackerCalibration& c, const char* what) {
    try {
      check_tracker_calibration(c);
      ADD_FAILURE() << "accepted: " << what;
    } catch (const ParameterError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  TrackerCalibration c = forty_stations();
  check_tracker_calibration(c);
  TrackerCalibration bad = c;
  bad.stations.clear();
  refused(bad, "station");
  bad = c;
  bad.stations[3][2] = NAN;
  refused(bad, "station 4");
  bad = c;
  bad.noise = 0.0;
  refused(bad, "noise");
  bad = c;
  bad.points = 0;
  refused(bad, "points");
  bad = c;
  bad.points = 1;
  refused(bad, "scatter");
  bad = c;
  bad.identification.model = CalibrationModel::Basic;
  refused(bad, "geometry");
  // The names a study's calibration may take.
  const std::vector<Pose> poses = workspace(0);
  for (const char* name : {"stations:0", "stations:x", "stations:5,", "stations:-3", "plan", "sometimes"}) {
    CalibrationChoice choice;
    choice.name = name;
    ToleranceOptions o;
    ToleranceLinear l;
    EXPECT_THROW((void)prepare_calibration(test::seed_model(), poses, choice, o, l), ParameterError) << name;
  }
}

TEST(ToleranceCalibration, TheTrackerCalibrationsAreTheOnesPrepareGivesATrackerStep) {
  // The front ends decide from is_tracker_calibration whether the tracker's options apply; the study
  // prepares a tracker step (its linear answer from the identification's covariance) for exactly those.
  const std::vector<Pose> poses = workspace(0);
  for (const char* name : {"none", "perfect", "stations:20", "stations:20,3", "plan"}) {
    SCOPED_TRACE(name);
    CalibrationChoice choice;
    choice.name = name;
    if (choice.name == "plan") choice.plan = random_station_plan(test::seed_model(), StationsSpec{.count = 20});
    ToleranceOptions o;
    ToleranceLinear l;
    ASSERT_EQ(prepare_calibration(test::seed_model(), poses, choice, o, l), Status::Ok);
    const bool tracker = std::string_view(name).starts_with("stations:") || choice.name == "plan";
    EXPECT_EQ(is_tracker_calibration(name), tracker);
    EXPECT_EQ(o.calibration != nullptr, choice.name != "none");
  }
  for (const char* name : {"Stations:4", "plan ", "stations", "tracker", ""})
    EXPECT_FALSE(is_tracker_calibration(name));
}

TEST(ToleranceCalibration, APlanOfTooFewStationsIsNotIdentifiableNotACrash) {
  // 5 and 13 stations give fewer equations than the geometric model (with every axis) has
  // parameters: the plan's Jacobian is wide, and the study says NotIdentifiable; 14 determine it.
  const std::vector<Pose> poses = workspace(0);
  for (const int n : {5, 13, 14}) {
    SCOPED_TRACE(n);
    CalibrationChoice choice;
    choice.name = "stations:" + std::to_string(n);
    ToleranceOptions o;
    ToleranceLinear l;
    EXPECT_EQ(prepare_calibration(test::seed_model(), poses, choice, o, l),
              n < 14 ? Status::NotIdentifiable : Status::Ok);
  }
}

}  // namespace
}  // namespace hexatwist
