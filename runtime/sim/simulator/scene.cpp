#include "runtime/sim/simulator/scene.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace fusecal::sim {

namespace {
constexpr float kTMin = 1e-4f;  // ignore hits closer than this (self-intersection)
constexpr float kEps = 1e-12f;

// log2(x) for x > 0 within about 1e-4: exponent plus a polynomial in the mantissa (mip selection only).
inline float FastLog2(float x) {
  uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const float exponent = static_cast<float>(static_cast<int>((bits >> 23) & 255) - 127);
  bits = (bits & 0x007FFFFFu) | 0x3F800000u;  // mantissa in [1, 2)
  float m;
  std::memcpy(&m, &bits, sizeof m);
  return exponent - 1.7417939f + m * (2.8212026f + m * (-1.4699568f + m * (0.44717955f - 0.056570851f * m)));
}
}  // namespace

int Scene::AddTexture(Texture texture) {
  textures_.push_back(std::move(texture));
  return static_cast<int>(textures_.size()) - 1;
}

int Scene::AddMaterial(const Material& material) {
  if (material.texture < 0 || material.texture >= static_cast<int>(textures_.size()))
    throw std::invalid_argument("material refers to a missing texture");
  if (!(material.tile_m > 0.0f)) throw std::invalid_argument("material tile_m must be positive");
  const Texture& tex = textures_[material.texture];
  Surface surface;
  surface.texture = material.texture;
  surface.s_per_m = 1.0f / material.tile_m;
  surface.t_per_m = -1.0f / (material.tile_m * static_cast<float>(tex.aspect()));
  surface.off_u_m = material.offset_u_m;
  surface.off_v_m = material.offset_v_m;
  surface.lod_bias = std::log2(tex.width() / material.tile_m);
  surface.gain = material.brightness;
  surfaces_.push_back(surface);
  return static_cast<int>(surfaces_.size()) - 1;
}

void Scene::AddQuad(const Eigen::Vector3f& center, const Eigen::Matrix3f& R_world_local, float half_x, float half_y,
                    int material) {
  Primitive p;
  p.shape = Shape::kQuad;
  p.R_local_world = R_world_local.transpose();
  p.center = center;
  p.half = Eigen::Vector3f(half_x, half_y, 0.0f);
  p.material = material;
  p.bound_radius = std::hypot(half_x, half_y);
  primitives_.push_back(p);
}

void Scene::AddBox(const Eigen::Vector3f& center, const Eigen::Matrix3f& R_world_local, const Eigen::Vector3f& half,
                   int material) {
  Primitive p;
  p.shape = Shape::kBox;
  p.R_local_world = R_world_local.transpose();
  p.center = center;
  p.half = half;
  p.material = material;
  p.bound_radius = half.norm();
  primitives_.push_back(p);
}

void Scene::AddCylinder(const Eigen::Vector3f& center, const Eigen::Matrix3f& R_world_local, float radius,
                        float half_height, int material) {
  Primitive p;
  p.shape = Shape::kCylinder;
  p.R_local_world = R_world_local.transpose();
  p.center = center;
  p.half = Eigen::Vector3f(radius, radius, half_height);
  p.material = material;
  p.bound_radius = std::hypot(radius, half_height);
  primitives_.push_back(p);
}

void Scene::Cull(const RayCone& cone, float tmax, std::vector<Candidate>* out) const {
  out->clear();
  for (int i = 0; i < static_cast<int>(primitives_.size()); ++i) {
    const Primitive& p = primitives_[i];
    const Eigen::Vector3f d = p.center - cone.origin;
    const float dist = d.norm();
    const float r = p.bound_radius + cone.slack;
    const float near = dist - r;
    if (near >= tmax) continue;
    if (dist > r) {
      // Sphere-cone test: the sphere subtends asin(r / dist) around d.
      const float sin_s = r / dist, cos_s = std::sqrt(std::max(0.0f, 1.0f - sin_s * sin_s));
      const float cos_sum = cone.cos_half * cos_s - cone.sin_half * sin_s;     // cos(half + s)
      const bool wide = cone.sin_half * cos_s + cone.cos_half * sin_s < 0.0f;  // half + s > pi
      if (!wide && cone.axis.dot(d) < cos_sum * dist) continue;
    }
    float bound = near;
    if (p.shape == Shape::kQuad) {
      // All rays of the cone must point towards the plane for a hit: cull when they all point away.
      const Eigen::Vector3f n = p.R_local_world.row(2).transpose();
      const float side = n.dot(cone.origin - p.center);
      if (std::abs(side) > cone.slack && cone.cos_half > 0.0f) {
        const Eigen::Vector3f towards = side > 0.0f ? Eigen::Vector3f(-n) : n;
        if (cone.axis.dot(towards) <= -cone.sin_half) continue;
      }
      bound = std::max(bound, std::abs(side) - cone.slack);  // no hit is nearer than the plane
    }
    out->push_back({i, bound});
  }
  std::sort(out->begin(), out->end(), [](const Candidate& a, const Candidate& b) {
    return a.near < b.near || (a.near == b.near && a.index < b.index);
  });
}

bool Scene::IntersectOne(const Primitive& p, const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float best,
                         Hit* hit) const {
  const Eigen::Vector3f oc = origin - p.center;
  if (p.shape == Shape::kQuad) {  // plane first: most rays miss it or hit it too far
    const float dz = p.R_local_world.row(2).dot(dir);
    if (std::abs(dz) < kEps) return false;
    const float t = -p.R_local_world.row(2).dot(oc) / dz;
    if (!(t > kTMin && t < best)) return false;
    const Eigen::Vector3f q = oc + t * dir;
    const float x = p.R_local_world.row(0).dot(q), y = p.R_local_world.row(1).dot(q);
    if (std::abs(x) > p.half.x() || std::abs(y) > p.half.y()) return false;
    *hit = {t, 0, 0, x, y, std::abs(dz)};
    return true;
  }
  const Eigen::Vector3f o = p.R_local_world * oc;
  const Eigen::Vector3f d = p.R_local_world * dir;
  switch (p.shape) {
    case Shape::kQuad:
      return false;  // handled above
    case Shape::kBox: {
      float tn = -std::numeric_limits<float>::infinity(), tf = std::numeric_limits<float>::infinity();
      int an = 0, af = 0;
      for (int k = 0; k < 3; ++k) {
        const float inv = 1.0f / d[k];
        float t1 = (-p.half[k] - o[k]) * inv, t2 = (p.half[k] - o[k]) * inv;
        if (t1 > t2) std::swap(t1, t2);
        if (t1 > tn) tn = t1, an = k;
        if (t2 < tf) tf = t2, af = k;
      }
      if (!(tn <= tf)) return false;
      const bool outside = tn > kTMin;
      const float t = outside ? tn : tf;
      const int axis = outside ? an : af;
      if (!(t > kTMin && t < best)) return false;
      const Eigen::Vector3f q = o + t * d;
      const int face = 2 * axis + (q[axis] > 0.0f ? 1 : 0);
      // In-face coordinates; v is local z on the side faces, so photos stand upright on upright boxes.
      const float u = axis == 0 ? q.y() : q.x();
      const float v = axis == 2 ? q.y() : q.z();
      *hit = {t, 0, face, u, v, std::abs(d[axis])};
      return true;
    }
    case Shape::kCylinder: {
      const float r = p.half.x(), h = p.half.z();
      bool found = false;
      const float a = d.x() * d.x() + d.y() * d.y();
      if (a > kEps) {
        const float b = o.x() * d.x() + o.y() * d.y();
        const float c = o.x() * o.x() + o.y() * o.y() - r * r;
        const float disc = b * b - a * c;
        if (disc >= 0.0f) {
          const float sq = std::sqrt(disc);
          for (float t : {(-b - sq) / a, (-b + sq) / a}) {
            if (!(t > kTMin && t < best)) continue;
            const Eigen::Vector3f q = o + t * d;
            if (std::abs(q.z()) > h) continue;
            const float cosi = std::abs(q.x() * d.x() + q.y() * d.y()) / r;
            *hit = {t, 0, 0, std::atan2(q.y(), q.x()) * r, q.z(), cosi};
            best = t;
            found = true;
            break;
          }
        }
      }
      if (std::abs(d.z()) > kEps) {
        for (int cap = 0; cap < 2; ++cap) {
          const float t = ((cap == 0 ? -h : h) - o.z()) / d.z();
          if (!(t > kTMin && t < best)) continue;
          const float x = o.x() + t * d.x(), y = o.y() + t * d.y();
          if (x * x + y * y > r * r) continue;
          *hit = {t, 0, 1 + cap, x, y, std::abs(d.z())};
          best = t;
          found = true;
        }
      }
      return found;
    }
  }
  return false;
}

bool Scene::Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, const Candidate* candidates, int n,
                      float tmax, Hit* hit, int* hint) const {
  float best = tmax;
  int found = -1;
  const int first = hint && *hint >= 0 && *hint < n ? *hint : -1;
  if (first >= 0 && IntersectOne(primitives_[candidates[first].index], origin, dir, best, hit)) {
    best = hit->t;
    found = first;
  }
  for (int i = 0; i < n; ++i) {
    if (candidates[i].near >= best) break;  // sorted: nothing further can be nearer
    if (i == first) continue;
    if (IntersectOne(primitives_[candidates[i].index], origin, dir, best, hit)) {
      best = hit->t;
      found = i;
    }
  }
  if (hint) *hint = found >= 0 ? found : *hint;
  if (found < 0) return false;
  hit->primitive = candidates[found].index;
  return true;
}

bool Scene::Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float tmax, Hit* hit) const {
  float best = tmax;
  int found = -1;
  for (int i = 0; i < static_cast<int>(primitives_.size()); ++i) {
    if (IntersectOne(primitives_[i], origin, dir, best, hit)) {
      best = hit->t;
      found = i;
    }
  }
  if (found < 0) return false;
  hit->primitive = found;
  return true;
}

const Texture& Scene::Lookup(const Hit& hit, float footprint_m, float* s, float* t, float* lod, float* gain) const {
  const Surface& m = surfaces_[primitives_[hit.primitive].material];
  // Each box face and cylinder cap shows a different part of the photo.
  const float face_u = 0.61f * hit.face, face_v = 0.37f * hit.face;
  *s = (hit.u + m.off_u_m + face_u) * m.s_per_m;
  *t = (hit.v + m.off_v_m + face_v) * m.t_per_m;
  // Oblique surfaces stretch the footprint along one direction: widen it by 1/sqrt(cos), between the
  // minor (no widening) and the major (1/cos) axis. lod = log2(footprint * widen * texels per metre).
  const float cosi = std::max(hit.cos_incidence, 0.05f);
  *lod = 0.5f * FastLog2(std::max(footprint_m * footprint_m / cosi, 1e-20f)) + m.lod_bias;
  *gain = m.gain;
  return textures_[m.texture];
}

float Scene::ShadeGrey(const Hit& hit, float footprint_m) const {
  float s, t, lod, gain;
  const Texture& tex = Lookup(hit, footprint_m, &s, &t, &lod, &gain);
  return std::min(255.0f, gain * tex.SampleGrey(s, t, lod));
}

void Scene::ShadeBgr(const Hit& hit, float footprint_m, float bgr[3]) const {
  float s, t, lod, gain;
  const Texture& tex = Lookup(hit, footprint_m, &s, &t, &lod, &gain);
  tex.SampleBgr(s, t, lod, bgr);
  for (int c = 0; c < 3; ++c) bgr[c] = std::min(255.0f, gain * bgr[c]);
}

float Scene::SkyGrey(const Eigen::Vector3f& dir) const { return 225.0f - 60.0f * std::max(0.0f, dir.z()); }

void Scene::SkyBgr(const Eigen::Vector3f& dir, float bgr[3]) const {
  const float up = std::max(0.0f, dir.z());
  bgr[0] = 240.0f - 20.0f * up;
  bgr[1] = 225.0f - 50.0f * up;
  bgr[2] = 210.0f - 90.0f * up;
}

}  // namespace fusecal::sim
