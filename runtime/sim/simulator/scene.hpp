// Textured scene geometry and a small ray caster: quads, oriented boxes, cylinders.
// World frame: z up. Primitives are few (tens), so each batch of rays (a tile) first culls them against
// the tile's bounding cone (Cull) and then tests the survivors near to far (Intersect).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "runtime/sim/simulator/texture.hpp"

namespace fusecal::sim {

struct Scenario;

struct Material {
  int texture = 0;
  float tile_m = 2.0f;      // world width of one copy of the photo (its height: tile_m * aspect)
  float offset_u_m = 0.0f;  // shifts the photo on the surface
  float offset_v_m = 0.0f;
  float brightness = 1.0f;  // multiplies the texture
};

enum class Shape : uint8_t { kQuad, kBox, kCylinder };

struct Primitive {
  Shape shape = Shape::kBox;
  Eigen::Matrix3f R_local_world = Eigen::Matrix3f::Identity();  // rows: local axes in world coordinates
  Eigen::Vector3f center = Eigen::Vector3f::Zero();
  // Quad: (half x, half y, 0), normal local z. Box: half extents. Cylinder: (radius, radius, half height)
  // about local z.
  Eigen::Vector3f half = Eigen::Vector3f::Ones();
  int material = 0;
  float bound_radius = 0.0f;  // bounding sphere about center
};

struct Hit {
  float t = 0.0f;  // distance along the (unit) ray
  int primitive = -1;
  int face = 0;                // box face 0..5, cylinder side 0 / caps 1, 2
  float u = 0.0f, v = 0.0f;    // surface coordinates, metres (v up on vertical faces)
  float cos_incidence = 1.0f;  // |cos| of the angle between ray and surface normal
};

// The bounding cone of a batch of rays: origins within `slack` of `origin`, directions within
// acos(cos_half) of `axis`.
struct RayCone {
  Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  Eigen::Vector3f axis = Eigen::Vector3f::UnitZ();
  float cos_half = 1.0f;
  float sin_half = 0.0f;
  float slack = 0.0f;
};

struct Candidate {
  int index;
  float near;  // lower bound of the distance to the primitive
};

class Scene {
 public:
  int AddTexture(Texture texture);
  int AddMaterial(const Material& material);  // throws when its texture does not exist
  // R_world_local: columns are the local axes in the world.
  void AddQuad(const Eigen::Vector3f& center, const Eigen::Matrix3f& R_world_local, float half_x, float half_y,
               int material);
  void AddBox(const Eigen::Vector3f& center, const Eigen::Matrix3f& R_world_local, const Eigen::Vector3f& half,
              int material);
  void AddCylinder(const Eigen::Vector3f& center, const Eigen::Matrix3f& R_world_local, float radius, float half_height,
                   int material);

  // Primitives that rays of the cone may hit before tmax, sorted by `near`.
  void Cull(const RayCone& cone, float tmax, std::vector<Candidate>* out) const;
  // Nearest hit in (0, tmax) among the candidates; `dir` must be unit. *hint (optional): position in
  // candidates of a likely hit (the previous ray's), tried first; updated to this ray's hit.
  bool Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, const Candidate* candidates, int n,
                 float tmax, Hit* hit, int* hint = nullptr) const;
  // Nearest hit among all primitives (no culling; for single rays).
  bool Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmax, Hit* hit) const;

  // Texture value at a hit, 0..255. footprint_m: width of the ray's footprint at the hit (pixel or beam
  // size times distance); it selects the mip level, widened on oblique surfaces.
  float ShadeGrey(const Hit& hit, float footprint_m) const;
  void ShadeBgr(const Hit& hit, float footprint_m, float bgr[3]) const;
  // Colour of rays that hit nothing (a plain sky gradient).
  float SkyGrey(const Eigen::Vector3f& dir) const;
  void SkyBgr(const Eigen::Vector3f& dir, float bgr[3]) const;

  const std::vector<Primitive>& primitives() const { return primitives_; }
  const std::vector<Texture>& textures() const { return textures_; }

 private:
  bool IntersectOne(const Primitive& p, const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float best,
                    Hit* hit) const;
  // A material prepared for lookups.
  struct Surface {
    int texture;
    float s_per_m, t_per_m;  // texture coordinates per metre (t runs down the photo)
    float off_u_m, off_v_m;
    float lod_bias;  // log2(texels per metre)
    float gain;
  };
  // Texture coordinates and level of detail of a hit.
  const Texture& Lookup(const Hit& hit, float footprint_m, float* s, float* t, float* lod, float* gain) const;

  std::vector<Texture> textures_;
  std::vector<Surface> surfaces_;  // one per material
  std::vector<Primitive> primitives_;
};

// Directory of the shipped textures (runtime/sim/simulator/textures in the source tree).
std::string DefaultTextureDir();

// The scene named by scenario.scene ("indoor" or "outdoor"), textured from texture_dir.
Scene BuildScene(const Scenario& scenario, const std::string& texture_dir = DefaultTextureDir());
Scene BuildIndoorScene(const std::string& texture_dir);
Scene BuildOutdoorScene(const std::string& texture_dir);

}  // namespace fusecal::sim
