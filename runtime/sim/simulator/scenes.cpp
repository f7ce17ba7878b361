// The two scene layouts. World frame: z up, metres. Every surface carries a photograph (see
// textures/README.md), each at its own scale and offset, so that image features are everywhere.
#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <stdexcept>

#include "runtime/sim/simulator/scenario.hpp"
#include "runtime/sim/simulator/scene.hpp"

#ifndef FUSECAL_TEXTURE_DIR
#define FUSECAL_TEXTURE_DIR "runtime/sim/simulator/textures"
#endif

namespace fusecal::sim {

std::string DefaultTextureDir() { return FUSECAL_TEXTURE_DIR; }

namespace {

using V3 = Eigen::Vector3f;

Eigen::Matrix3f Yaw(float deg) {
  return Eigen::AngleAxisf(deg * static_cast<float>(M_PI) / 180.0f, V3::UnitZ()).toRotationMatrix();
}

// Rotation whose columns are x_axis, y_axis and their cross product.
Eigen::Matrix3f Frame(const V3& x_axis, const V3& y_axis) {
  Eigen::Matrix3f R;
  R << x_axis, y_axis, x_axis.cross(y_axis);
  return R;
}

// Scene under construction, with textures loaded once by file name.
class Builder {
 public:
  explicit Builder(std::string dir) : dir_(std::move(dir)) {}

  int Mat(const std::string& texture, float tile_m, float off_u = 0.0f, float off_v = 0.0f, float gain = 1.0f) {
    auto it = ids_.find(texture);
    if (it == ids_.end()) it = ids_.emplace(texture, scene_.AddTexture(Texture::Load(dir_, texture))).first;
    return scene_.AddMaterial({it->second, tile_m, off_u, off_v, gain});
  }
  // Upright rectangle (a wall) from floor corner a to b, from height z0 to z1; the photo reads from a
  // to b for a viewer with a on the left.
  void Wall(const V3& a, const V3& b, float z0, float z1, int mat) {
    const V3 along = (b - a).normalized();
    const V3 center = 0.5f * (a + b) + V3(0, 0, 0.5f * (z0 + z1));
    scene_.AddQuad(center, Frame(along, V3::UnitZ()), 0.5f * (b - a).norm(), 0.5f * (z1 - z0), mat);
  }
  void Horizontal(const V3& center, float half_x, float half_y, int mat) {
    scene_.AddQuad(center, Eigen::Matrix3f::Identity(), half_x, half_y, mat);
  }
  // Box standing on z = z0 (centre x, y), yawed by yaw_deg.
  void Box(float x, float y, float z0, const V3& half, float yaw_deg, int mat) {
    scene_.AddBox(V3(x, y, z0 + half.z()), Yaw(yaw_deg), half, mat);
  }
  // Upright cylinder from z0 to z1. Its texture repeats seamlessly around it when tile_m = pi r / k.
  void Pillar(float x, float y, float r, float z0, float z1, int mat) {
    scene_.AddCylinder(V3(x, y, 0.5f * (z0 + z1)), Eigen::Matrix3f::Identity(), r, 0.5f * (z1 - z0), mat);
  }
  Scene Take() { return std::move(scene_); }

 private:
  std::string dir_;
  std::map<std::string, int> ids_;
  Scene scene_;
};

}  // namespace

// A 10 x 8 x 3 m room: x in [-5, 5], y in [-4, 4], z in [0, 3]; furniture along the walls, three
// pillars; the middle (around the rig start, (0.4, 0.3, 1.5)) is free.
Scene BuildIndoorScene(const std::string& texture_dir) {
  Builder b(texture_dir);
  const float h = 3.0f;
  b.Horizontal(V3(0, 0, 0), 5, 4, b.Mat("board.jpg", 2.4f));
  b.Horizontal(V3(0, 0, h), 5, 4, b.Mat("aero1.jpg", 3.0f, 0.4f, 0.2f));
  // Walls run clockwise seen from above, so the photos read left to right from inside the room.
  b.Wall(V3(5, 4, 0), V3(5, -4, 0), 0, h, b.Mat("graf1.jpg", 3.2f, 0.3f));
  b.Wall(V3(-5, 4, 0), V3(5, 4, 0), 0, h, b.Mat("graf3.jpg", 3.4f, 1.1f));
  b.Wall(V3(-5, -4, 0), V3(-5, 4, 0), 0, h, b.Mat("leuvenA.jpg", 3.0f, 0.2f));
  b.Wall(V3(5, -4, 0), V3(-5, -4, 0), 0, h, b.Mat("building.jpg", 3.0f, 0.7f));

  b.Box(4.55f, -1.8f, 0, V3(0.4f, 0.9f, 1.0f), 0, b.Mat("baboon.jpg", 1.2f));              // cabinet
  b.Box(-4.5f, 1.0f, 0, V3(0.45f, 1.3f, 0.9f), 0, b.Mat("fruits.jpg", 1.0f));              // shelf
  b.Box(-2.4f, -2.2f, 0, V3(0.8f, 0.5f, 0.4f), 25, b.Mat("rubberwhale1.jpg", 1.5f));       // table
  b.Box(2.2f, -2.6f, 0, V3(0.35f, 0.35f, 0.35f), 35, b.Mat("box_in_scene.jpg", 0.9f));     // crate
  b.Box(2.6f, 2.7f, 0, V3(0.6f, 0.45f, 0.6f), -15, b.Mat("aloeL.jpg", 1.2f));              // stack
  b.Box(-0.8f, 3.3f, 0, V3(1.2f, 0.3f, 0.25f), 5, b.Mat("baboon.jpg", 1.0f, 0.5f, 0.3f));  // bench
  b.Box(-3.4f, 3.1f, 0, V3(0.3f, 0.3f, 0.3f), 10, b.Mat("fruits.jpg", 0.8f, 0.2f));        // crate
  b.Box(1.2f, -3.6f, 0, V3(0.5f, 0.3f, 1.0f), 0, b.Mat("leuvenA.jpg", 1.0f, 0.4f));        // locker
  b.Box(0.0f, -3.6f, 2.6f, V3(4.5f, 0.2f, 0.15f), 0, b.Mat("graf1.jpg", 1.0f, 0.1f));      // duct

  const float r = 0.25f, k = static_cast<float>(M_PI) * r;
  b.Pillar(-2.0f, 0.6f, r, 0, h, b.Mat("aloeL.jpg", k));
  b.Pillar(2.4f, -0.4f, r, 0, h, b.Mat("graf3.jpg", k, 0.0f, 0.5f));
  b.Pillar(0.9f, 2.4f, r, 0, h, b.Mat("fruits.jpg", k));
  return b.Take();
}

// A street canyon along x: ground, building blocks on both sides (fronts at y = +-8 m), blocks closing
// both ends, parked cars, poles, and towers 70-100 m away. The rig starts at (0, 0, 1.8).
Scene BuildOutdoorScene(const std::string& texture_dir) {
  Builder b(texture_dir);
  b.Horizontal(V3(0, 0, 0), 150, 150, b.Mat("aero1.jpg", 4.0f));

  b.Box(-12, 14, 0, V3(9, 6, 7), 0, b.Mat("building.jpg", 12.0f));
  b.Box(6, 13, 0, V3(8, 5, 5), 0, b.Mat("leuvenA.jpg", 9.0f));
  b.Box(22, 14, 0, V3(7, 6, 9), 0, b.Mat("graf1.jpg", 8.0f));
  b.Box(-10, -13, 0, V3(8, 5, 6), 0, b.Mat("leuvenA.jpg", 10.0f, 3.0f));
  b.Box(7, -12.5f, 0, V3(8, 4.5f, 8), 0, b.Mat("building.jpg", 14.0f, 5.0f));
  b.Box(24, -14, 0, V3(7, 6, 5), 0, b.Mat("graf3.jpg", 8.0f));
  b.Box(40, 0, 0, V3(5, 12, 10), 0, b.Mat("building.jpg", 11.0f, 2.0f));
  b.Box(-38, 0, 0, V3(5, 14, 6), 0, b.Mat("graf1.jpg", 10.0f, 4.0f));

  b.Box(80, 40, 0, V3(8, 8, 25), 20, b.Mat("building.jpg", 20.0f, 7.0f));
  b.Box(-70, -50, 0, V3(10, 10, 30), -10, b.Mat("leuvenA.jpg", 22.0f));
  b.Box(20, 90, 0, V3(12, 6, 20), 5, b.Mat("graf3.jpg", 18.0f));
  b.Box(-30, -95, 0, V3(15, 8, 15), 0, b.Mat("building.jpg", 16.0f, 3.0f));

  b.Box(-3, 5.5f, 0, V3(2.1f, 0.9f, 0.75f), 0, b.Mat("rubberwhale1.jpg", 2.0f));  // parked cars
  b.Box(9, -5.5f, 0, V3(2.2f, 0.9f, 0.8f), 0, b.Mat("fruits.jpg", 2.0f));
  b.Box(-14, -5.6f, 0, V3(2.0f, 0.85f, 0.7f), 3, b.Mat("baboon.jpg", 2.0f));
  b.Box(18, 5.8f, 0, V3(2.0f, 0.5f, 0.4f), 0, b.Mat("aloeL.jpg", 1.5f));  // planter

  const float r = 0.12f, k = static_cast<float>(M_PI) * r;
  const int pole = b.Mat("box_in_scene.jpg", k);
  for (const auto& [x, y] : {std::pair{-6.0f, 6.5f}, {4.0f, 6.5f}, {14.0f, 6.5f}, {-2.0f, -6.5f}, {10.0f, -6.5f}})
    b.Pillar(x, y, r, 0, 6, pole);
  return b.Take();
}

Scene BuildScene(const Scenario& scenario, const std::string& texture_dir) {
  if (scenario.scene == "indoor") return BuildIndoorScene(texture_dir);
  if (scenario.scene == "outdoor") return BuildOutdoorScene(texture_dir);
  throw std::invalid_argument("unknown scene '" + scenario.scene + "'");
}

}  // namespace fusecal::sim
