// The common result file, the export formats (round trips), and `fusecal evaluate`/`export`.
#include <gtest/gtest.h>
#include <unistd.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "support/process_utils.hpp"
#include "formats/extrinsic_formats.hpp"
#include "formats/result_file.hpp"

namespace fusecal {
namespace {

using testing_utils::RunCommand;

CalibrationResult SampleResult() {
  CalibrationResult r;
  r.T_camera_lidar = MakeIsometry(RotationFromRpy(-1.55, 0.02, -1.58), {0.06, -0.12, -0.08});
  Matrix6 c = Matrix6::Zero();
  c.diagonal() << 1e-6, 4e-6, 9e-6, 1e-4, 4e-4, 9e-4;
  r.covariance = c;
  r.status = "converged";
  r.observability = "ok";
  r.motions_used = {"0-1", "1-2"};
  r.motions_rejected = {"2-3: rotation angles differ by 2.0 deg"};
  r.residual_rms = 0.0012;
  return r;
}

std::string TempFile(const std::string& name) {
  return testing::TempDir() + "fusecal_" + std::to_string(getpid()) + "_" + name;
}

TEST(ResultFile, WriteThenReadKeepsTheTransform) {
  const std::string path = TempFile("result.yaml");
  const CalibrationResult r = SampleResult();
  CalibrationResult initial = r;
  initial.status = "initial";
  WriteResultFile(path, r, &initial);
  const CalibrationResult back = ReadResultFile(path);
  EXPECT_LT((back.T_camera_lidar.matrix() - r.T_camera_lidar.matrix()).norm(), 1e-9);
  EXPECT_EQ(back.status, "converged");
  ASSERT_TRUE(back.covariance.has_value());
  EXPECT_NEAR(TranslationStdDevM(*back.covariance).z(), 0.03, 1e-12);
  const std::string text = ResultToYaml(r, &initial);
  for (const char* key : {"translation_m:", "rotation_quaternion_wxyz:", "rotation_rpy_deg:", "std_dev:",
                          "observability:", "motions_used:", "motions_rejected:", "residual_rms:", "initial:"})
    EXPECT_NE(text.find(key), std::string::npos) << key;
}

TEST(ResultFile, OnlyTheMatrixIsRequiredAndBadMatricesAreNamed) {
  const std::string path = TempFile("minimal.yaml");
  std::ofstream(path) << "T_camera_lidar: [1,0,0,0.1, 0,1,0,0.2, 0,0,1,0.3, 0,0,0,1]\n";
  EXPECT_NEAR(ReadResultFile(path).T_camera_lidar.translation().y(), 0.2, 1e-12);
  std::ofstream(path, std::ios::trunc) << "T_camera_lidar: [1,2,3]\n";
  try {
    ReadResultFile(path);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("T_camera_lidar"), std::string::npos);
  }
  std::ofstream(path, std::ios::trunc) << "T_camera_lidar: [2,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,0,1]\n";
  EXPECT_THROW(ReadResultFile(path), std::runtime_error);
  EXPECT_THROW(ReadResultFile(TempFile("missing.yaml")), std::runtime_error);
}

TEST(ExportFormats, EveryFormatRoundTrips) {
  const CalibrationResult r = SampleResult();
  for (const auto& format : ExportFormats()) {
    const std::string text = ExportExtrinsic(r, format);
    const Isometry3 back = ParseExportedExtrinsic(text, format);
    EXPECT_LT(RotationErrorDeg(back.linear(), r.T_camera_lidar.linear()), 1e-7) << format << "\n" << text;
    EXPECT_LT((back.translation() - r.T_camera_lidar.translation()).norm(), 1e-9) << format;
  }
  EXPECT_THROW(ExportExtrinsic(r, "urdf"), std::invalid_argument);
  EXPECT_THROW(ParseExportedExtrinsic("R: 1 2 3\n", "kitti"), std::runtime_error);
}

TEST(Commands, EvaluateAndExport) {
  const std::string result = TempFile("est.yaml"), truth = TempFile("truth.yaml");
  CalibrationResult r = SampleResult();
  WriteResultFile(truth, r);
  r.T_camera_lidar = r.T_camera_lidar * MakeIsometry(ExpSO3({0, 0, 0.5 * M_PI / 180}), {0, 0, 0});
  r.T_camera_lidar.translation() += Eigen::Vector3d(0.03, 0, -0.04);
  WriteResultFile(result, r);
  const auto eval = RunCommand(std::string(FUSECAL_BIN) + " evaluate --result " + result + " --truth " + truth);
  ASSERT_EQ(eval.exit_code, 0);
  const auto j = nlohmann::json::parse(eval.output);
  EXPECT_NEAR(j["rot_err_deg"].get<double>(), 0.5, 1e-6);
  EXPECT_NEAR(j["trans_err_m"].get<double>(), 0.05, 1e-9);
  EXPECT_EQ(j["trans_err_xyz_m"].size(), 3u);

  const std::string out = TempFile("tf.txt");
  const auto exported =
      RunCommand(std::string(FUSECAL_BIN) + " export " + result + " --format ros-static-tf --out " + out);
  ASSERT_EQ(exported.exit_code, 0);
  std::ifstream in(out);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("camera lidar"), std::string::npos);
  EXPECT_EQ(RunCommand(std::string(FUSECAL_BIN) + " export " + result + " --format urdf 2>&1").exit_code == 0,
            false);
  EXPECT_EQ(RunCommand(std::string(FUSECAL_BIN) + " evaluate --result /nonexistent.yaml --truth " + truth +
                       " 2>&1")
                .exit_code,
            1);
}

}  // namespace
}  // namespace fusecal
