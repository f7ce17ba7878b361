// Unit tests of the hand-eye solver core on synthetic motions (no bus, no files).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "stages/handeye/handeye_solver.hpp"
#include "stages/handeye/synthetic_motions.hpp"

namespace fusecal {
namespace {

constexpr double kDeg = M_PI / 180.0;

SyntheticMotionSettings Motions(int n, std::uint32_t seed, double rot_noise_deg = 0.0, double trans_noise_m = 0.0) {
  SyntheticMotionSettings s;
  s.num_motions = n;
  s.seed = seed;
  s.rotation_noise_deg = rot_noise_deg;
  s.translation_noise_m = trans_noise_m;
  return s;
}

double RotErrRad(const HandEyeResult& r, const Isometry3& X) {
  return RotationErrorRad(r.T_camera_lidar.linear(), X.linear());
}
double TransErrM(const HandEyeResult& r, const Isometry3& X) {
  return (r.T_camera_lidar.translation() - X.translation()).norm();
}
bool Parallel(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol) {
  return a.norm() > 0.5 && std::abs(std::abs(a.normalized().dot(b.normalized())) - 1.0) < tol;
}

// --- Settings ----------------------------------------------------------------------------------------------

TEST(HandEyeResult, DefaultIsNotUsableAndVerdictsHaveTheirNames) {
  const HandEyeResult r;
  EXPECT_FALSE(r.usable());
  EXPECT_EQ(r.failure_reason.code, HandEyeFailure::kNotRun);
  EXPECT_STREQ(Name(r.status), "failed");
  EXPECT_STREQ(Name(r.observability), "too_few_motions");
  EXPECT_STREQ(Name(HandEyeStatus::kConverged), "converged");
  EXPECT_STREQ(Name(HandEyeStatus::kNotConverged), "not_converged");
  EXPECT_STREQ(Name(HandEyeStatus::kDegenerate), "degenerate");
  EXPECT_STREQ(Name(Observability::kOk), "ok");
  EXPECT_STREQ(Name(Observability::kRotationDegenerate), "rotation_degenerate");
  EXPECT_STREQ(Name(Observability::kTranslationPartlyUnobservable), "translation_partly_unobservable");
}

TEST(HandEyeSettings, DefaultsAreValidAndBadValuesAreNamed) {
  HandEyeSettings s;
  EXPECT_EQ(s.Validate(), "");
  EXPECT_TRUE(s.IsValid());
  s.min_pairs = 1;
  std::string error;
  EXPECT_FALSE(s.IsValid(&error));
  EXPECT_NE(error.find("min_pairs"), std::string::npos);

  const auto data = GenerateSyntheticMotions(Motions(10, 1));
  const HandEyeResult r = SolveScaled(data.pairs, s);
  EXPECT_EQ(r.status, HandEyeStatus::kFailed);
  EXPECT_FALSE(r.usable());
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.failure_reason.code, HandEyeFailure::kInvalidSettings);
  EXPECT_EQ(r.failure_reason.text, r.message);
  EXPECT_NE(r.message.find("invalid settings"), std::string::npos) << r.message;
}

// --- Noise-free recovery -------------------------------------------------------------------------------------

TEST(HandEyeNoiseFree, ScaledRecoversExtrinsicExactly) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    const auto data = GenerateSyntheticMotions(Motions(10, seed));
    const HandEyeResult r = SolveScaled(data.pairs);
    EXPECT_TRUE(r.converged) << r.message;
    EXPECT_EQ(r.status, HandEyeStatus::kConverged);
    EXPECT_EQ(r.observability, Observability::kOk);
    EXPECT_TRUE(r.rejected_pairs.empty()) << r.rejected_pairs.front().reason;
    EXPECT_EQ(r.used_pairs.size(), 10u);
    EXPECT_LT(RotErrRad(r, data.T_camera_lidar), 1e-9);
    EXPECT_LT(TransErrM(r, data.T_camera_lidar), 1e-9);
    EXPECT_LT(r.residual_rms_rot_deg, 1e-7);
    EXPECT_LT(r.residual_rms_trans_m, 1e-9);
    EXPECT_TRUE(r.scales.empty());
  }
}

TEST(HandEyeNoiseFree, ScalelessRecoversExtrinsicAndScalesExactly) {
  for (std::uint32_t seed = 1; seed <= 5; ++seed) {
    auto settings = Motions(10, seed);
    settings.scaleless = true;
    const auto data = GenerateSyntheticMotions(settings);
    const HandEyeResult r = SolveScaleless(data.pairs);
    EXPECT_TRUE(r.converged) << r.message;
    EXPECT_EQ(r.observability, Observability::kOk);
    EXPECT_LT(RotErrRad(r, data.T_camera_lidar), 1e-9);
    EXPECT_LT(TransErrM(r, data.T_camera_lidar), 1e-9);
    ASSERT_EQ(r.scales.size(), data.true_scales.size());
    for (size_t k = 0; k < r.scales.size(); ++k) EXPECT_NEAR(r.scales[k], data.true_scales[k], 1e-9);
  }
}

TEST(HandEyeNoiseFree, ScaledIgnoresAPoorInitialGuess) {
  const auto data = GenerateSyntheticMotions(Motions(8, 7));
  const Isometry3 bad = data.T_camera_lidar * MakeIsometry(RotationFromRpy(1.5, -0.5, 2.0), {1.0, -1.0, 0.5});
  const HandEyeResult r = SolveScaled(data.pairs, {}, &bad);
  EXPECT_TRUE(r.converged) << r.message;
  EXPECT_LT(RotErrRad(r, data.T_camera_lidar), 1e-9);
  EXPECT_LT(TransErrM(r, data.T_camera_lidar), 1e-9);
}

// --- Noise ---------------------------------------------------------------------------------------------------

TEST(HandEyeNoise, ErrorShrinksWithMoreMotions) {
  const int trials = 30;
  for (bool scaleless : {false, true}) {
    double rot[2] = {0, 0}, trans[2] = {0, 0};
    for (int which = 0; which < 2; ++which) {
      for (int k = 0; k < trials; ++k) {
        auto s = Motions(which == 0 ? 3 : 20, 100 + k, 0.1, 0.005);
        s.scaleless = scaleless;
        const auto data = GenerateSyntheticMotions(s);
        const HandEyeResult r = scaleless ? SolveScaleless(data.pairs) : SolveScaled(data.pairs);
        rot[which] += RotErrRad(r, data.T_camera_lidar) / trials;
        trans[which] += TransErrM(r, data.T_camera_lidar) / trials;
      }
    }
    SCOPED_TRACE(scaleless ? "scaleless" : "scaled");
    EXPECT_LT(rot[1], 0.6 * rot[0]) << "3 motions: " << rot[0] / kDeg << " deg, 20: " << rot[1] / kDeg;
    EXPECT_LT(trans[1], 0.6 * trans[0]) << "3 motions: " << trans[0] << " m, 20: " << trans[1];
    EXPECT_LT(rot[1], 0.2 * kDeg);
    EXPECT_LT(trans[1], 0.02);
  }
}

// Fraction of per-axis errors within one standard deviation (expected 0.683 for honest uncertainties).
struct Coverage {
  int rot_in = 0, trans_in = 0, n = 0;
  void Add(const HandEyeResult& r, const Isometry3& truth) {
    const Vector6 e = ExtrinsicError(r.T_camera_lidar, truth);
    for (int k = 0; k < 3; ++k) {
      rot_in += std::abs(e(k)) <= std::sqrt(r.covariance(k, k));
      trans_in += std::abs(e(k + 3)) <= std::sqrt(r.covariance(k + 3, k + 3));
      ++n;
    }
  }
  double Rot() const { return double(rot_in) / n; }
  double Trans() const { return double(trans_in) / n; }
};

// An honest 1-sigma: about 68% of per-axis errors inside it, for rotation and translation alike.
void ExpectAbout68Percent(const Coverage& c) {
  EXPECT_GT(c.Rot(), 0.55);
  EXPECT_LT(c.Rot(), 0.80);
  EXPECT_GT(c.Trans(), 0.55);
  EXPECT_LT(c.Trans(), 0.80);
}

TEST(HandEyeUncertainty, ScaledOneSigmaCoverageIsAbout68Percent) {
  Coverage c;
  for (int k = 0; k < 200; ++k) {
    const auto data = GenerateSyntheticMotions(Motions(10, 1000 + k, 0.1, 0.005));
    const HandEyeResult r = SolveScaled(data.pairs);
    ASSERT_EQ(r.observability, Observability::kOk) << r.message;
    c.Add(r, data.T_camera_lidar);
  }
  ExpectAbout68Percent(c);
  std::cout << "scaled coverage: rotation " << c.Rot() << ", translation " << c.Trans() << "\n";
}

TEST(HandEyeUncertainty, ScalelessOneSigmaCoverageIsAbout68Percent) {
  Coverage c;
  for (int k = 0; k < 200; ++k) {
    auto s = Motions(10, 2000 + k, 0.1, 0.005);
    s.scaleless = true;
    const auto data = GenerateSyntheticMotions(s);
    const HandEyeResult r = SolveScaleless(data.pairs);
    ASSERT_EQ(r.observability, Observability::kOk) << r.message;
    c.Add(r, data.T_camera_lidar);
  }
  ExpectAbout68Percent(c);
  std::cout << "scaleless coverage: rotation " << c.Rot() << ", translation " << c.Trans() << "\n";
}

TEST(HandEyeUncertainty, ScaledWithInputCovariancesIsHonest) {
  Coverage c;
  for (int k = 0; k < 200; ++k) {
    auto s = Motions(10, 3000 + k, 0.05, 0.01);
    s.attach_covariance = true;
    const auto data = GenerateSyntheticMotions(s);
    const HandEyeResult r = SolveScaled(data.pairs);
    c.Add(r, data.T_camera_lidar);
  }
  ExpectAbout68Percent(c);
}

// --- Degenerate sets -----------------------------------------------------------------------------------------

TEST(HandEyeDegenerate, ScaledSingleAxisLeavesTranslationAlongAxisUnobservable) {
  // Planar motion: all rotations about LiDAR z, translations varied. The rotation is still determined (through
  // the translations), t along the axis is not.
  for (double noise : {0.0, 1.0}) {
    auto s = Motions(10, 11, 0.1 * noise, 0.005 * noise);
    s.axes = {Eigen::Vector3d::UnitZ()};
    const auto data = GenerateSyntheticMotions(s);
    const HandEyeResult r = SolveScaled(data.pairs);
    EXPECT_EQ(r.observability, Observability::kTranslationPartlyUnobservable) << r.message;
    EXPECT_EQ(r.status, HandEyeStatus::kDegenerate);
    EXPECT_FALSE(r.converged);
    const Eigen::Vector3d k_a = data.T_camera_lidar.linear() * Eigen::Vector3d::UnitZ();
    EXPECT_TRUE(Parallel(r.unobservable_direction, k_a, 1e-3)) << r.unobservable_direction.transpose();
    // What is observable is recovered: rotation, and t across the axis.
    const Eigen::Vector3d dt = r.T_camera_lidar.translation() - data.T_camera_lidar.translation();
    EXPECT_LT(RotErrRad(r, data.T_camera_lidar), noise > 0 ? 0.2 * kDeg : 1e-9);
    EXPECT_LT((dt - k_a * k_a.dot(dt)).norm(), noise > 0 ? 0.02 : 1e-9);
    // The covariance says t along the axis is unknown.
    EXPECT_GT(k_a.dot(r.covariance.bottomRightCorner<3, 3>() * k_a), 1.0);
  }
}

TEST(HandEyeDegenerate, ScaledRotationsAboutOneLineLeaveRotationUnobservable) {
  for (double noise : {0.0, 1.0}) {
    auto s = Motions(10, 12, 0.1 * noise, 0.005 * noise);
    s.axes = {Eigen::Vector3d::UnitY()};
    s.max_translation_m = 0.0;  // every screw axis is the LiDAR's y axis
    const auto data = GenerateSyntheticMotions(s);
    const HandEyeResult r = SolveScaled(data.pairs);
    EXPECT_EQ(r.observability, Observability::kRotationDegenerate) << r.message;
    EXPECT_EQ(r.status, HandEyeStatus::kDegenerate);
    EXPECT_FALSE(r.converged);
    const Eigen::Vector3d k_a = data.T_camera_lidar.linear() * Eigen::Vector3d::UnitY();
    EXPECT_TRUE(Parallel(r.unobservable_direction, k_a, 1e-3)) << r.unobservable_direction.transpose();
    // The axis itself is mapped correctly.
    EXPECT_LT(std::acos(std::min(1.0, (r.T_camera_lidar.linear() * Eigen::Vector3d::UnitY()).dot(k_a))),
              noise > 0 ? 0.5 * kDeg : 1e-7);
  }
}

TEST(HandEyeDegenerate, UnobservableDirectionsKeepTheInitialGuess) {
  // Planar, noisy: t along the axis is 0 without an initial guess, the guess's value with one.
  auto s = Motions(10, 18, 0.1, 0.005);
  s.axes = {Eigen::Vector3d::UnitZ()};
  const auto planar = GenerateSyntheticMotions(s);
  const Isometry3& X = planar.T_camera_lidar;
  const Eigen::Vector3d k_a = X.linear() * Eigen::Vector3d::UnitZ();
  const HandEyeResult r0 = SolveScaled(planar.pairs);
  ASSERT_TRUE(Parallel(r0.unobservable_direction, k_a, 1e-3));
  EXPECT_NEAR(r0.unobservable_direction.dot(r0.T_camera_lidar.translation()), 0.0, 1e-9);
  Isometry3 guess = X;
  guess.translation() += 0.3 * k_a + Eigen::Vector3d(0.05, 0.05, 0.05);
  const HandEyeResult r1 = SolveScaled(planar.pairs, {}, &guess);
  EXPECT_EQ(r1.observability, Observability::kTranslationPartlyUnobservable);
  const Eigen::Vector3d d = r1.unobservable_direction;
  EXPECT_NEAR(d.dot(r1.T_camera_lidar.translation()), d.dot(guess.translation()), 1e-9);
  EXPECT_LT(
      (r1.T_camera_lidar.translation() - X.translation() - d * d.dot(guess.translation() - X.translation())).norm(),
      0.02);

  // Rotations about one line, noise-free: with the true extrinsic as the guess, the result is exact.
  auto c = Motions(6, 19);
  c.axes = {Eigen::Vector3d::UnitX()};
  c.max_translation_m = 0.0;
  const auto line = GenerateSyntheticMotions(c);
  for (bool scaled : {true, false}) {
    auto pairs = line.pairs;
    if (!scaled)
      for (auto& p : pairs) p.camera_scaled = false;
    const HandEyeResult r =
        scaled ? SolveScaled(pairs, {}, &line.T_camera_lidar) : SolveScaleless(pairs, {}, &line.T_camera_lidar);
    EXPECT_EQ(r.observability, Observability::kRotationDegenerate);
    EXPECT_FALSE(r.converged);
    EXPECT_LT(RotErrRad(r, line.T_camera_lidar), 1e-9);
    EXPECT_LT(TransErrM(r, line.T_camera_lidar), 1e-9);
  }
}

TEST(HandEyeDegenerate, ScalelessSingleAxisIsRotationDegenerate) {
  auto s = Motions(10, 13);
  s.axes = {Eigen::Vector3d::UnitX()};
  s.scaleless = true;
  const auto data = GenerateSyntheticMotions(s);
  const HandEyeResult r = SolveScaleless(data.pairs);
  EXPECT_EQ(r.observability, Observability::kRotationDegenerate) << r.message;
  EXPECT_FALSE(r.converged);
  const Eigen::Vector3d k_a = data.T_camera_lidar.linear() * Eigen::Vector3d::UnitX();
  EXPECT_TRUE(Parallel(r.unobservable_direction, k_a, 1e-3));
  EXPECT_GE(r.std_dev_rot_deg.maxCoeff(), 1.0);
}

TEST(HandEyeDegenerate, ScaledTwoAxesAreObservable) {
  auto s = Motions(10, 14, 0.1, 0.005);
  s.axes = {Eigen::Vector3d::UnitZ(), Eigen::Vector3d::UnitY()};  // yaw and pitch, as the paper recommends
  const auto data = GenerateSyntheticMotions(s);
  const HandEyeResult r = SolveScaled(data.pairs);
  EXPECT_EQ(r.observability, Observability::kOk) << r.message;
  EXPECT_TRUE(r.converged);
}

TEST(HandEyeDegenerate, PureTranslationsAreTooFewMotions) {
  auto s = Motions(6, 15);
  s.min_angle_deg = s.max_angle_deg = 0.0;
  const auto data = GenerateSyntheticMotions(s);
  for (bool scaled : {true, false}) {
    const HandEyeResult r = scaled ? SolveScaled(data.pairs) : SolveScaleless(data.pairs);
    EXPECT_EQ(r.observability, Observability::kTooFewMotions);
    EXPECT_EQ(r.status, HandEyeStatus::kFailed);
    EXPECT_FALSE(r.converged);
    ASSERT_EQ(r.rejected_pairs.size(), 6u);
    EXPECT_NE(r.rejected_pairs[0].reason.find("no rotation"), std::string::npos) << r.rejected_pairs[0].reason;
    EXPECT_FALSE(r.message.empty());
  }
}

// A car driving straight: translations along one line, rotations of a few hundredths of a degree.
TEST(HandEyeDegenerate, DrivingStraightObservesOnlyTheDirectionOfTravel) {
  const Isometry3 X = MakeIsometry(ExpSO3(Eigen::Vector3d(1.2, -1.1, 1.3)), Eigen::Vector3d(0.05, -0.08, -0.27));
  std::vector<MotionPair> pairs;
  Eigen::Vector3d travel_sum = Eigen::Vector3d::Zero();
  for (int i = 0; i < 5; ++i) {
    MotionPair p;
    p.station_i = i;
    p.station_j = i + 1;
    const double wobble = 0.02 * kDeg * (i % 2 ? 1 : -1);
    p.B = MakeIsometry(ExpSO3(Eigen::Vector3d(0, wobble, -wobble)),
                       Eigen::Vector3d(0.5 + 0.4 * i, 0.01 * i, 0.002 * (i % 3)));
    travel_sum += p.B.translation();
    p.A = X * p.B * X.inverse();
    p.A.translation() = p.A.translation().normalized();  // scaleless: a direction only
    p.camera_scaled = false;
    pairs.push_back(p);
  }
  const HandEyeResult r = SolveScaleless(pairs);
  EXPECT_EQ(r.status, HandEyeStatus::kFailed);
  EXPECT_EQ(r.failure_reason.code, HandEyeFailure::kTooFewPairs);
  EXPECT_EQ(r.failure_reason.text, r.message);  // with the description of the travel
  EXPECT_EQ(r.observability, Observability::kTooFewMotions);
  const Eigen::Vector3d travel_b = travel_sum.normalized();  // the mean direction, weighted by distance
  const Eigen::Vector3d travel_a = X.linear() * travel_b;
  EXPECT_TRUE(Parallel(r.unobservable_direction, travel_a, 1e-4)) << r.unobservable_direction.transpose();
  // The estimate maps the direction of travel right; the rotation about it is arbitrary.
  EXPECT_LT(std::acos(std::min(1.0, (r.T_camera_lidar.linear() * travel_b).dot(travel_a))), 0.5 * kDeg);
  EXPECT_NE(r.message.find("rotation about the direction of travel"), std::string::npos) << r.message;
  EXPECT_NE(r.message.find("whole translation"), std::string::npos) << r.message;
}

TEST(HandEyeDegenerate, TwoMotionsAreTooFewButStillEstimated) {
  const auto data = GenerateSyntheticMotions(Motions(2, 16));
  const HandEyeResult r = SolveScaled(data.pairs);
  EXPECT_EQ(r.observability, Observability::kTooFewMotions);
  EXPECT_EQ(r.status, HandEyeStatus::kDegenerate);
  EXPECT_TRUE(r.usable());
  EXPECT_EQ(r.failure_reason.code, HandEyeFailure::kNone);
  EXPECT_TRUE(r.failure_reason.text.empty());
  EXPECT_FALSE(r.converged);
  EXPECT_LT(RotErrRad(r, data.T_camera_lidar), 1e-9);  // best estimate still returned
  EXPECT_LT(TransErrM(r, data.T_camera_lidar), 1e-9);

  HandEyeSettings two;
  two.min_pairs = 2;
  EXPECT_TRUE(SolveScaled(data.pairs, two).converged);

  auto sl = Motions(2, 16);
  sl.scaleless = true;
  const HandEyeResult r2 = SolveScaleless(GenerateSyntheticMotions(sl).pairs);
  EXPECT_EQ(r2.observability, Observability::kTooFewMotions);
  EXPECT_FALSE(r2.converged);
}

TEST(HandEyeDegenerate, OneMotionFails) {
  const auto data = GenerateSyntheticMotions(Motions(1, 17));
  for (bool scaled : {true, false}) {
    const HandEyeResult r = scaled ? SolveScaled(data.pairs) : SolveScaleless(data.pairs);
    EXPECT_EQ(r.observability, Observability::kTooFewMotions);
    EXPECT_EQ(r.status, HandEyeStatus::kFailed);
    EXPECT_FALSE(r.converged);
    EXPECT_NE(r.message.find("too few"), std::string::npos) << r.message;
  }
}

// --- Outliers ------------------------------------------------------------------------------------------------

TEST(HandEyeOutliers, AngleMismatchIsRejectedAndNamed) {
  auto data = GenerateSyntheticMotions(Motions(8, 21, 0.05, 0.003));
  MotionPair& bad = data.pairs[3];
  bad.A.linear() =
      bad.A.linear() * ExpSO3(Eigen::Vector3d(0.0, 0.0, 10.0 * kDeg));  // the limit: 1 deg + 10 % of the angle
  const HandEyeResult r = SolveScaled(data.pairs);
  ASSERT_EQ(r.rejected_pairs.size(), 1u);
  EXPECT_EQ(r.rejected_pairs[0].station_i, bad.station_i);
  EXPECT_EQ(r.rejected_pairs[0].station_j, bad.station_j);
  EXPECT_EQ(r.rejected_pairs[0].index, 3);
  EXPECT_NE(r.rejected_pairs[0].reason.find("angles disagree"), std::string::npos) << r.rejected_pairs[0].reason;
  EXPECT_FALSE(r.IsUsed(bad.station_i, bad.station_j));
  EXPECT_TRUE(r.converged);
}

TEST(HandEyeOutliers, RightAngleWrongAxisIsRejectedAndNamed) {
  for (bool scaled : {true, false}) {
    SCOPED_TRACE(scaled ? "scaled" : "scaleless");
    auto s = Motions(10, 22, 0.05, 0.003);
    s.scaleless = !scaled;
    auto data = GenerateSyntheticMotions(s);
    MotionPair& bad = data.pairs[6];
    // Same angle, axis turned by 40 degrees: passes the angle screening.
    const Eigen::Vector3d w = LogSO3(bad.A.linear());
    const Eigen::Vector3d other = w.unitOrthogonal();
    bad.A.linear() = ExpSO3(Eigen::AngleAxisd(40.0 * kDeg, other).toRotationMatrix() * w);
    const HandEyeResult r = scaled ? SolveScaled(data.pairs) : SolveScaleless(data.pairs);
    ASSERT_EQ(r.rejected_pairs.size(), 1u) << r.message;
    EXPECT_EQ(r.rejected_pairs[0].station_i, 6);
    EXPECT_EQ(r.rejected_pairs[0].station_j, 7);
    EXPECT_NE(r.rejected_pairs[0].reason.find("outlier"), std::string::npos) << r.rejected_pairs[0].reason;
    EXPECT_TRUE(r.IsRejected(6, 7));
    EXPECT_EQ(r.used_pairs.size(), 9u);
    EXPECT_LT(RotErrRad(r, data.T_camera_lidar), 0.1 * kDeg);
    EXPECT_LT(TransErrM(r, data.T_camera_lidar), 0.02);
  }
}

TEST(HandEyeOutliers, WrongCameraTranslationIsRejected) {
  auto data = GenerateSyntheticMotions(Motions(10, 23, 0.05, 0.003));
  data.pairs[2].A.translation() += Eigen::Vector3d(0.2, -0.1, 0.1);
  const HandEyeResult r = SolveScaled(data.pairs);
  ASSERT_EQ(r.rejected_pairs.size(), 1u) << r.message;
  EXPECT_EQ(r.rejected_pairs[0].station_i, 2);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(TransErrM(r, data.T_camera_lidar), 0.02);
}

TEST(HandEyeOutliers, FlippedScalelessDirectionIsRejected) {
  auto s = Motions(10, 24, 0.05, 0.003);
  s.scaleless = true;
  auto data = GenerateSyntheticMotions(s);
  data.pairs[5].A.translation() *= -1.0;
  const HandEyeResult r = SolveScaleless(data.pairs);
  ASSERT_EQ(r.rejected_pairs.size(), 1u) << r.message;
  EXPECT_EQ(r.rejected_pairs[0].station_i, 5);
  for (double scale : r.scales) EXPECT_GT(scale, 0.0);
  EXPECT_LT(TransErrM(r, data.T_camera_lidar), 0.03);
}

// --- Bad input -----------------------------------------------------------------------------------------------

TEST(HandEyeBadInput, NonFiniteAndNonOrthonormalPairsAreRejectedWithReason) {
  auto data = GenerateSyntheticMotions(Motions(8, 31));
  data.pairs[1].A(0, 3) = std::numeric_limits<double>::quiet_NaN();
  data.pairs[4].B.linear() *= 1.01;
  data.pairs[6].cov_A = Matrix6::Identity() * -1.0;
  for (bool scaled : {true, false}) {
    const HandEyeResult r = scaled ? SolveScaled(data.pairs) : SolveScaleless(data.pairs);
    ASSERT_EQ(r.rejected_pairs.size(), 3u) << r.message;
    EXPECT_EQ(r.rejected_pairs[0].station_i, 1);
    EXPECT_NE(r.rejected_pairs[0].reason.find("non-finite"), std::string::npos);
    EXPECT_EQ(r.rejected_pairs[1].station_i, 4);
    EXPECT_NE(r.rejected_pairs[1].reason.find("not orthonormal"), std::string::npos);
    EXPECT_EQ(r.rejected_pairs[2].station_i, 6);
    EXPECT_NE(r.rejected_pairs[2].reason.find("cov_A"), std::string::npos);
    EXPECT_TRUE(r.converged) << r.message;
    EXPECT_TRUE(r.T_camera_lidar.matrix().allFinite());
    EXPECT_LT(RotErrRad(r, data.T_camera_lidar), 1e-9);
  }
}

TEST(HandEyeBadInput, EmptyInputFailsWithMessage) {
  for (bool scaled : {true, false}) {
    const HandEyeResult r = scaled ? SolveScaled({}) : SolveScaleless({});
    EXPECT_EQ(r.status, HandEyeStatus::kFailed);
    EXPECT_FALSE(r.usable());
    EXPECT_EQ(r.failure_reason.code, HandEyeFailure::kTooFewPairs);
    EXPECT_FALSE(r.converged);
    EXPECT_NE(r.message.find("too few"), std::string::npos);
    EXPECT_TRUE(r.T_camera_lidar.matrix().isIdentity());
  }
}

TEST(HandEyeBadInput, AllNaNInputFailsWithoutThrowing) {
  auto data = GenerateSyntheticMotions(Motions(5, 32));
  for (auto& p : data.pairs) p.B.linear()(1, 1) = std::numeric_limits<double>::infinity();
  HandEyeResult r;
  EXPECT_NO_THROW(r = SolveScaled(data.pairs));
  EXPECT_EQ(r.status, HandEyeStatus::kFailed);
  EXPECT_EQ(r.rejected_pairs.size(), 5u);
}

TEST(HandEyeBadInput, ScalelessMotionsAreRejectedByTheScaledSolve) {
  auto s = Motions(6, 33);
  s.scaleless = true;
  const auto data = GenerateSyntheticMotions(s);
  const HandEyeResult r = SolveScaled(data.pairs);
  EXPECT_EQ(r.status, HandEyeStatus::kFailed);
  ASSERT_EQ(r.rejected_pairs.size(), 6u);
  EXPECT_NE(r.rejected_pairs[0].reason.find("camera_scaled"), std::string::npos);
}

TEST(HandEyeBadInput, InvalidInitialGuessFails) {
  const auto data = GenerateSyntheticMotions(Motions(6, 34));
  Isometry3 initial = Isometry3::Identity();
  initial.linear() *= 2.0;
  const HandEyeResult r = SolveScaled(data.pairs, {}, &initial);
  EXPECT_EQ(r.status, HandEyeStatus::kFailed);
  EXPECT_EQ(r.failure_reason.code, HandEyeFailure::kInvalidInitialGuess);
  EXPECT_NE(r.message.find("initial"), std::string::npos);
}

// --- Synthetic generator -------------------------------------------------------------------------------------

TEST(SyntheticMotions, DeterministicAndConsistent) {
  const auto a = GenerateSyntheticMotions(Motions(5, 41, 0.1, 0.01));
  const auto b = GenerateSyntheticMotions(Motions(5, 41, 0.1, 0.01));
  const auto c = GenerateSyntheticMotions(Motions(5, 42, 0.1, 0.01));
  ASSERT_EQ(a.pairs.size(), 5u);
  EXPECT_TRUE(a.pairs[4].A.isApprox(b.pairs[4].A, 0.0));
  EXPECT_FALSE(a.pairs[4].A.isApprox(c.pairs[4].A));
  const Isometry3& X = a.T_camera_lidar;
  for (size_t k = 0; k < 5; ++k) {
    EXPECT_TRUE((a.A_true[k] * X).isApprox(X * a.B_true[k], 1e-12));
    const double angle = RotationAngle(a.B_true[k].linear()) / kDeg;
    EXPECT_GE(angle, 10.0 - 1e-9);
    EXPECT_LE(angle, 45.0 + 1e-9);
  }
}

}  // namespace
}  // namespace fusecal
