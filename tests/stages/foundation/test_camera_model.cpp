#include <gtest/gtest.h>

#include <cmath>

#include "stages/foundation/camera_model.hpp"

namespace fusecal {
namespace {

CameraParams DistortedPinhole() {
  CameraParams p;
  p.model = "pinhole";
  p.width = 1280;
  p.height = 720;
  p.fx = 640;
  p.fy = 642;
  p.cx = 639.5;
  p.cy = 359.5;
  p.dist = {-0.18, 0.05, 0.0012, -0.0008, -0.005};
  return p;
}

CameraParams Panorama() {
  CameraParams p;
  p.model = "equirectangular";
  p.width = 2048;
  p.height = 1024;
  return p;
}

CameraParams Fisheye() {  // a 190-degree lens on a 1024 x 1024 sensor (coefficients of a real calibration)
  CameraParams p;
  p.model = "equidistant";
  p.width = 1024;
  p.height = 1024;
  p.fx = 290;
  p.fy = 291;
  p.cx = 511.5;
  p.cy = 510.0;
  p.dist = {0.021, -0.0061, 0.0009, -0.0002, 0};
  return p;
}

// pixel -> bearing -> pixel over the whole image, every `stride` pixels plus the last row/column.
double WorstRoundTripError(const CameraModel& camera, int stride) {
  double worst = 0;
  auto check = [&](double u, double v) {
    const Eigen::Vector2d pixel(u, v);
    const Eigen::Vector3d bearing = camera.Unproject(pixel);
    EXPECT_NEAR(bearing.norm(), 1.0, 1e-12);
    Eigen::Vector2d back;
    EXPECT_TRUE(camera.Project(bearing * 3.7, &back)) << "pixel " << u << "," << v;
    double error = (back - pixel).norm();
    if (camera.WrapsHorizontally()) error = std::min(error, std::abs(std::abs(back.x() - u) - camera.width()));
    worst = std::max(worst, error);
  };
  for (int v = 0; v < camera.height(); v += stride)
    for (int u = 0; u < camera.width(); u += stride) check(u, v);
  for (int v = 0; v < camera.height(); v += stride) check(camera.width() - 1, v);
  for (int u = 0; u < camera.width(); u += stride) check(u, camera.height() - 1);
  check(-0.5, -0.5);
  check(camera.width() - 0.5, camera.height() - 0.5);
  return worst;
}

TEST(CameraModel, PinholeWithDistortionRoundTripsBelowMicroPixel) {
  const auto camera = MakeCameraModel(DistortedPinhole());
  EXPECT_LT(WorstRoundTripError(*camera, 4), 1e-6);
}

TEST(CameraModel, EquirectangularRoundTripsBelowMicroPixel) {
  const auto camera = MakeCameraModel(Panorama());
  EXPECT_LT(WorstRoundTripError(*camera, 4), 1e-6);
}

TEST(CameraModel, EquidistantRoundTripsBelowMicroPixelInsideItsImageCircle) {
  const auto camera = MakeCameraModel(Fisheye());
  double worst = 0;
  for (int v = 0; v < camera->height(); v += 4)
    for (int u = 0; u < camera->width(); u += 4) {
      const Eigen::Vector3d bearing = camera->Unproject({u, v});
      Eigen::Vector2d back;
      if (std::acos(bearing.z()) > 95.0 * M_PI / 180.0) continue;  // corners lie outside the image circle
      ASSERT_TRUE(camera->Project(bearing * 2.5, &back)) << u << "," << v;
      worst = std::max(worst, (back - Eigen::Vector2d(u, v)).norm());
    }
  EXPECT_LT(worst, 1e-6);
}

TEST(CameraModel, EquidistantMatchesTheKannalaBrandtFormulaAndSeesBehindNinetyDegrees) {
  const CameraParams p = Fisheye();
  const auto camera = MakeCameraModel(p);
  const double theta = 0.7;  // 40 degrees off axis, towards +x +y
  const Eigen::Vector3d ray(std::sin(theta) * 0.6, std::sin(theta) * 0.8, std::cos(theta));
  const auto& k = p.dist;
  const double theta_d = theta * (1 + k[0] * std::pow(theta, 2) + k[1] * std::pow(theta, 4) +
                                  k[2] * std::pow(theta, 6) + k[3] * std::pow(theta, 8));
  Eigen::Vector2d pixel;
  ASSERT_TRUE(camera->Project(ray, &pixel));
  EXPECT_NEAR(pixel.x(), p.fx * theta_d * 0.6 + p.cx, 1e-9);
  EXPECT_NEAR(pixel.y(), p.fy * theta_d * 0.8 + p.cy, 1e-9);
  const double side = 95.0 * M_PI / 180.0;  // slightly behind the image plane: a pinhole cannot see it
  EXPECT_TRUE(camera->Project({std::sin(side), 0, std::cos(side)}, &pixel));
  EXPECT_FALSE(camera->Project({0, 0, -1}, &pixel));
}

TEST(CameraModel, PinholeWithoutDistortionMatchesProjectionFormula) {
  CameraParams p = DistortedPinhole();
  p.dist = {0, 0, 0, 0, 0};
  const auto camera = MakeCameraModel(p);
  Eigen::Vector2d pixel;
  ASSERT_TRUE(camera->Project({0.5, -0.25, 2.0}, &pixel));
  EXPECT_NEAR(pixel.x(), p.fx * 0.25 + p.cx, 1e-12);
  EXPECT_NEAR(pixel.y(), p.fy * -0.125 + p.cy, 1e-12);
}

TEST(CameraModel, PinholeRejectsPointsBehindAndOutside) {
  const auto camera = MakeCameraModel(DistortedPinhole());
  Eigen::Vector2d pixel;
  EXPECT_FALSE(camera->Project({0, 0, -1}, &pixel));
  EXPECT_FALSE(camera->Project({100, 0, 1}, &pixel));  // far outside the monotonic range
  EXPECT_FALSE(camera->Project({std::nan(""), 0, 1}, &pixel));
}

TEST(CameraModel, EquirectangularAxisConvention) {
  const auto camera = MakeCameraModel(Panorama());
  Eigen::Vector2d pixel;
  ASSERT_TRUE(camera->Project({0, 0, 1}, &pixel));  // forward: image centre
  EXPECT_NEAR(pixel.x(), 1023.5, 1e-9);
  EXPECT_NEAR(pixel.y(), 511.5, 1e-9);
  ASSERT_TRUE(camera->Project({1, 0, 0}, &pixel));  // right: three quarters across
  EXPECT_NEAR(pixel.x(), 1535.5, 1e-9);
  ASSERT_TRUE(camera->Project({0, -1, 0}, &pixel));  // up (-y): top border
  EXPECT_NEAR(pixel.y(), -0.5, 1e-9);
}

TEST(CameraModel, InvalidParametersNameTheField) {
  CameraParams p = DistortedPinhole();
  p.fx = -1;
  try {
    MakeCameraModel(p);
    FAIL() << "negative fx accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("fx"), std::string::npos) << e.what();
  }
  p = Panorama();
  p.model = "fisheye";
  EXPECT_THROW(MakeCameraModel(p), std::invalid_argument);
  p = Panorama();
  p.height = 0;
  EXPECT_NE(p.Validate().find("height"), std::string::npos);
}

}  // namespace
}  // namespace fusecal
