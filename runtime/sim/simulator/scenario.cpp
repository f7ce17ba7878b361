#include "runtime/sim/simulator/scenario.hpp"

#include <cmath>
#include <filesystem>

#include "runtime/config_reader.hpp"

#ifndef FUSECAL_SCENARIO_DIR
#define FUSECAL_SCENARIO_DIR "configs/scenarios"
#endif

namespace fusecal::sim {

std::vector<double> LidarParams::ElevationsRad() const {
  std::vector<double> out;
  if (!elevations_deg.empty()) {
    for (double e : elevations_deg) out.push_back(e * M_PI / 180.0);
    return out;
  }
  for (int i = 0; i < beams; ++i) {
    const double f = beams > 1 ? static_cast<double>(i) / (beams - 1) : 0.5;
    out.push_back((elevation_max_deg + f * (elevation_min_deg - elevation_max_deg)) * M_PI / 180.0);
  }
  return out;
}

int LidarParams::Columns() const {
  if (!Repetitive()) return std::max(1, static_cast<int>(std::lround(point_rate_hz / (rate_hz * beams))));
  return std::max(1, static_cast<int>(std::lround(360.0 / azimuth_resolution_deg)));
}

std::string DefaultScenarioDir() { return FUSECAL_SCENARIO_DIR; }

int Scenario::CameraIndex(const std::string& camera_name) const {
  for (size_t i = 0; i < cameras.size(); ++i)
    if (cameras[i].name == camera_name) return static_cast<int>(i);
  return -1;
}

namespace {

using Vec = std::vector<double>;

// A frame's rays live in memory at once (12 bytes each, plus a range and an intensity per ray).
constexpr double kMaxRaysPerFrame = 1 << 27;
// The frame times of a whole session are listed in memory.
constexpr double kMaxFramesPerSession = 2e7;

Check<Vec> SizeIs(size_t n) {
  return [n](const Vec& v) {
    if (v.size() != n) return "must be a list of " + std::to_string(n) + " numbers";
    for (double x : v)
      if (!std::isfinite(x)) return std::string("must hold finite numbers");
    return std::string();
  };
}

// [min, max] with 0 <= min <= max (< hi).
Check<Vec> RangePair(double hi) {
  return [hi](const Vec& v) {
    std::string e = SizeIs(2)(v);
    if (!e.empty()) return e;
    if (v[0] < 0 || v[1] < v[0] || v[1] > hi) return "must be [min, max] with 0 <= min <= max <= " + std::to_string(hi);
    return std::string();
  };
}

Eigen::Vector3d ToVector3(const Vec& v) { return {v[0], v[1], v[2]}; }

// Roll, pitch, yaw in degrees and a translation as in extrinsic.rpy_deg and xyz_m.
Isometry3 FromRpyXyz(const Vec& rpy_deg, const Vec& xyz) {
  const double d2r = M_PI / 180.0;
  return MakeIsometry(RotationFromRpy(rpy_deg[0] * d2r, rpy_deg[1] * d2r, rpy_deg[2] * d2r), ToVector3(xyz));
}

// The keys of a camera: of the `camera:` section, or of an entry of `cameras:` (which has its name and
// extrinsic besides; the caller reads those and finishes the reader).
void ReadCameraKeys(ConfigReader& r, CameraSettings* cam) {
  CameraParams& p = cam->params;
  r.Require("model", &p.model, OneOf({"pinhole", "equirectangular"}));
  r.Require("width", &p.width, Positive<int>());
  r.Require("height", &p.height, Positive<int>());
  const bool pinhole = p.model == "pinhole";
  r.Get("fx", &p.fx, Positive<double>(), pinhole);
  r.Get("fy", &p.fy, Positive<double>(), pinhole);
  r.Get("cx", &p.cx, Check<double>(), pinhole);
  r.Get("cy", &p.cy, Check<double>(), pinhole);
  Vec dist(p.dist.begin(), p.dist.end());
  r.Get("dist", &dist, SizeIs(5));
  std::copy(dist.begin(), dist.end(), p.dist.begin());
  r.Get("rate_hz", &cam->rate_hz, Positive<double>());
  r.Get("phase_s", &cam->phase_s, NonNegative<double>());
  r.Get("supersample", &cam->supersample, InRange(1, 8));
  r.Get("moving_supersample", &cam->moving_supersample, InRange(1, 8));
  r.Get("moving_scale", &cam->moving_scale, InRange(0.1, 1.0));
  r.Get("color", &cam->color);
  const double rays = static_cast<double>(p.width) * p.height * cam->supersample * cam->supersample;
  if (rays > kMaxRaysPerFrame)
    r.Fail(p.width >= p.height ? "width" : "height",
           std::to_string(p.width) + " x " + std::to_string(p.height) + " pixels x " +
               std::to_string(cam->supersample * cam->supersample) + " rays per pixel (supersample^2) is " +
               std::to_string(static_cast<int64_t>(rays)) + " rays per image: at most " +
               std::to_string(static_cast<int64_t>(kMaxRaysPerFrame)) + " fit in memory");
  const std::string problem = p.Validate();  // "field: what"
  if (!problem.empty()) {
    const auto colon = problem.find(':');
    r.Fail(problem.substr(0, colon), problem.substr(colon + 2));
  }
}

void ReadCamera(ConfigReader r, CameraSettings* cam) {
  ReadCameraKeys(r, cam);
  r.Finish();
}

// Model-dependent defaults: a terrestrial scanner (panoramic), Livox Avia-like (rosette: 6 lines,
// 240k points/s, 70.4 x 77.2 deg) and Mid-360-like (petal: 4 lines, 200k points/s, -7 to 52 deg).
void SetModelDefaults(LidarParams* l) {
  if (l->model == "panoramic") {
    l->beams = 600;
    l->elevation_max_deg = 90.0;
    l->elevation_min_deg = -60.0;
    l->azimuth_resolution_deg = 0.25;
    l->min_range_m = 0.5;
    l->max_range_m = 150.0;
    l->beam_divergence_mrad = 0.5;
  } else if (l->model == "rosette") {
    l->beams = 6;
    l->point_rate_hz = 240000.0;
    l->min_range_m = 1.0;
    l->max_range_m = 190.0;
    l->beam_divergence_mrad = 3.0;
  } else if (l->model == "petal") {
    l->beams = 4;
    l->point_rate_hz = 200000.0;
    l->elevation_max_deg = 52.0;
    l->elevation_min_deg = -7.0;
    l->min_range_m = 0.1;
    l->max_range_m = 70.0;
    l->beam_divergence_mrad = 3.0;
  }
}

void ReadPattern(ConfigReader& r, LidarParams* l) {
  r.Get("point_rate_hz", &l->point_rate_hz, InRange(1000.0, 1e8));
  r.Get("field_of_view_deg", &l->field_of_view_deg, Check<Vec>([](const Vec& v) {
          std::string e = SizeIs(2)(v);
          if (e.empty() && !(v[0] > 0 && v[0] <= 180.0 && v[1] > 0 && v[1] <= 180.0))
            e = "must be [horizontal, vertical] within (0, 180]";
          return e;
        }));
}

void ReadLidar(ConfigReader r, LidarParams* l) {
  r.Require("model", &l->model, OneOf({"multibeam", "panoramic", "rosette", "petal"}));
  SetModelDefaults(l);
  r.Get("beams", &l->beams, InRange(1, 4096), l->Repetitive());
  if (!l->Repetitive()) ReadPattern(r, l);
  Vec elevation{l->elevation_max_deg, l->elevation_min_deg};
  r.Get("elevation_deg", &elevation, Check<Vec>([](const Vec& v) {
          std::string e = SizeIs(2)(v);
          if (e.empty() && !(v[0] >= v[1] && v[0] <= 90.0 && v[1] >= -90.0))
            e = "must be [max, min] with -90 <= min <= max <= 90";
          return e;
        }));
  l->elevation_max_deg = elevation[0];
  l->elevation_min_deg = elevation[1];
  const int beams = l->beams;
  r.Get("elevations_deg", &l->elevations_deg, Check<Vec>([beams](const Vec& v) {
          if (static_cast<int>(v.size()) != beams) return std::string("must list one elevation per beam");
          for (size_t i = 0; i < v.size(); ++i) {
            if (!(std::abs(v[i]) <= 90.0)) return std::string("must be within [-90, 90]");
            if (i > 0 && !(v[i] < v[i - 1])) return std::string("must be strictly decreasing (top first)");
          }
          return std::string();
        }));
  r.Get("azimuth_resolution_deg", &l->azimuth_resolution_deg, InRange(0.01, 10.0));
  r.Get("min_range_m", &l->min_range_m, NonNegative<double>());
  r.Get("max_range_m", &l->max_range_m, Positive<double>());
  if (l->max_range_m <= l->min_range_m) r.Fail("max_range_m", "must exceed min_range_m");
  r.Get("rate_hz", &l->rate_hz, Positive<double>());
  r.Get("phase_s", &l->phase_s, NonNegative<double>());
  r.Get("beam_divergence_mrad", &l->beam_divergence_mrad, NonNegative<double>());
  r.Get("motion_distortion", &l->motion_distortion);
  const double rays = static_cast<double>(l->beams) * l->Columns();
  if (rays > kMaxRaysPerFrame)
    r.Fail(l->Repetitive() ? "azimuth_resolution_deg" : "point_rate_hz",
           "gives " + std::to_string(l->beams) + " x " + std::to_string(l->Columns()) + " rays per scan: at most " +
               std::to_string(static_cast<int64_t>(kMaxRaysPerFrame)) + " fit in memory");
  r.Finish();
}

void ReadExtrinsic(ConfigReader r, Isometry3* T) {
  Vec xyz, rpy;
  r.Require("xyz_m", &xyz, SizeIs(3));
  r.Require("rpy_deg", &rpy, SizeIs(3));
  r.Finish();
  *T = FromRpyXyz(rpy, xyz);
}

// A camera's name: 1-32 characters of [A-Za-z0-9_], starting with a letter (it ends channel names).
std::string CheckCameraName(const std::string& name) {
  const auto letter = [](char c) { return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z'); };
  if (name.empty() || name.size() > 32) return "must have 1 to 32 characters";
  if (!letter(name[0])) return "must start with a letter";
  for (char c : name)
    if (!letter(c) && !(c >= '0' && c <= '9') && c != '_')
      return "must hold only letters, digits and _ (it ends the camera's channel names)";
  return std::string();
}

// The rig's cameras: either `camera:` and `extrinsic:` (one camera, no name) or `cameras:`, a list of
// named cameras, each with the keys of `camera:` and its own `extrinsic:`.
void ReadCameras(ConfigReader& r, Scenario* s) {
  const bool one = r.Has("camera"), several = r.Has("cameras");
  if (one && several)
    r.Fail("cameras",
           "and 'camera' are both given: a scenario has either one camera (camera: and extrinsic:) or "
           "a list of named cameras (cameras:, each with its own extrinsic:)");
  if (!one && !several) r.Fail("camera", "is required (or cameras:, a list of named cameras)");
  if (one) {
    if (!r.Has("extrinsic")) r.Fail("extrinsic", "is required");
    RigCamera camera;
    ReadCamera(r.Child("camera"), &camera.settings);
    ReadExtrinsic(r.Child("extrinsic"), &camera.T_camera_lidar);
    s->cameras = {camera};
    return;
  }
  if (r.Has("extrinsic"))
    r.Fail("extrinsic", "goes inside each entry of cameras: (cameras[k].extrinsic), not beside it");
  std::vector<ConfigReader> items = r.Items("cameras");
  if (items.empty()) r.Fail("cameras", "must list one camera at least");
  s->cameras.clear();
  for (ConfigReader& item : items) {
    RigCamera camera;
    item.Require("name", &camera.name, Check<std::string>(CheckCameraName));
    for (size_t k = 0; k < s->cameras.size(); ++k)
      if (s->cameras[k].name == camera.name)
        item.Fail("name",
                  "'" + camera.name + "' is the name of cameras[" + std::to_string(k) + "] too: names are unique");
    ReadCameraKeys(item, &camera.settings);
    if (!item.Has("extrinsic")) item.Fail("extrinsic", "is required");
    ReadExtrinsic(item.Child("extrinsic"), &camera.T_camera_lidar);
    item.Finish();
    s->cameras.push_back(camera);
  }
}

// extrinsic_changes: a list of {after_stop, delta_rpy_deg, delta_xyz_m, camera}; camera (a name, default
// the first camera) says which camera moved; a change needs a motion after its stop, and each camera's
// stops increase.
void ReadExtrinsicChanges(ConfigReader& r, const Scenario& s, std::vector<ExtrinsicChange>* changes) {
  const MotionParams& m = s.motions;
  const int stops = m.horizontal + m.vertical + 1;
  for (ConfigReader item : r.Items("extrinsic_changes")) {
    ExtrinsicChange c;
    std::string camera = s.cameras.front().name;
    item.Get("camera", &camera, Check<std::string>([&s](const std::string& name) {
               if (s.CameraIndex(name) >= 0) return std::string();
               if (s.cameras.size() == 1 && s.cameras.front().name.empty())
                 return std::string("names no camera: the rig's one camera (camera:) has no name, leave the key out");
               std::string names;
               for (const RigCamera& rc : s.cameras) names += (names.empty() ? "" : ", ") + rc.name;
               return "must name a camera of cameras: (" + names + ")";
             }));
    c.camera = s.CameraIndex(camera);
    const ExtrinsicChange* previous = nullptr;  // the same camera's
    for (const ExtrinsicChange& other : *changes)
      if (other.camera == c.camera) previous = &other;
    item.Require("after_stop", &c.after_stop, Check<int>([stops](const int& v) {
                   if (v >= 1 && v <= stops - 1) return std::string();
                   return "must be in [1, " + std::to_string(stops - 1) + "]: a stop (counted from 1) with a " +
                          "motion after it, of the scenario's " + std::to_string(stops) + " stops";
                 }));
    if (previous && c.after_stop <= previous->after_stop)
      item.Fail("after_stop", camera.empty()
                                  ? "must exceed the previous change's after_stop (" +
                                        std::to_string(previous->after_stop) + "): one change per stop, in order"
                                  : "must exceed the after_stop (" + std::to_string(previous->after_stop) +
                                        ") of camera " + camera +
                                        "'s previous change: one change per stop and camera, in order");
    Vec rpy, xyz;
    item.Require("delta_rpy_deg", &rpy, SizeIs(3));
    item.Require("delta_xyz_m", &xyz, SizeIs(3));
    item.Finish();
    c.delta = FromRpyXyz(rpy, xyz);
    changes->push_back(c);
  }
}

void ReadMotions(ConfigReader r, MotionParams* m) {
  r.Require("horizontal", &m->horizontal, InRange(0, 1000));
  r.Require("vertical", &m->vertical, InRange(0, 1000));
  Vec rot{m->rotation_min_deg, m->rotation_max_deg};
  r.Require("rotation_deg", &rot, RangePair(170.0));
  m->rotation_min_deg = rot[0];
  m->rotation_max_deg = rot[1];
  Vec tilt{m->tilt_min_deg, m->tilt_max_deg};
  r.Get("tilt_deg", &tilt, RangePair(45.0));
  m->tilt_min_deg = tilt[0];
  m->tilt_max_deg = tilt[1];
  r.Get("still_s", &m->still_s, Positive<double>());
  Vec move{m->move_min_s, m->move_max_s};
  r.Get("move_s", &move, RangePair(600.0));
  if (move[0] <= 0) r.Fail("move_s", "must be positive");
  m->move_min_s = move[0];
  m->move_max_s = move[1];
  r.Get("translation_m", &m->translation_m, NonNegative<double>());
  r.Get("max_drift_m", &m->max_drift_m, NonNegative<double>());
  Vec yaw_pivot(m->yaw_pivot_m.data(), m->yaw_pivot_m.data() + 3);
  r.Get("yaw_pivot_m", &yaw_pivot, SizeIs(3));
  m->yaw_pivot_m = ToVector3(yaw_pivot);
  Vec tilt_pivot(m->tilt_pivot_m.data(), m->tilt_pivot_m.data() + 3);
  r.Get("tilt_pivot_m", &tilt_pivot, SizeIs(3));
  m->tilt_pivot_m = ToVector3(tilt_pivot);
  r.Get("tilt_axis", &m->tilt_axis, OneOf({"pitch", "roll", "alternate"}));
  r.Get("order", &m->order, OneOf({"alternate", "grouped"}));
  r.Finish();
}

void ReadNoise(ConfigReader r, NoiseParams* n, LidarParams* l) {
  r.Require("image_sigma", &n->image_sigma, InRange(0.0, 100.0));
  r.Require("lidar_range_sigma_m", &l->range_sigma_m, InRange(0.0, 10.0));
  r.Get("exposure_sigma", &n->exposure_sigma, InRange(0.0, 1.0));
  r.Get("lidar_dropout", &l->dropout, InRange(0.0, 1.0));
  r.Get("lidar_intensity_sigma", &l->intensity_sigma, InRange(0.0, 1.0));
  r.Finish();
}

void ReadRig(ConfigReader r, Scenario* s) {
  Vec pos(s->rig_position_m.data(), s->rig_position_m.data() + 3);
  r.Get("position_m", &pos, SizeIs(3));
  s->rig_position_m = ToVector3(pos);
  r.Get("yaw_deg", &s->rig_yaw_deg, InRange(-360.0, 360.0));
  r.Finish();
}

// The longest session the motions can make, and its frames, must fit in memory.
void CheckSessionLength(ConfigReader& r, const Scenario& s) {
  const MotionParams& m = s.motions;
  const double seconds = (m.horizontal + m.vertical + 1.0) * m.still_s + (m.horizontal + m.vertical) * m.move_max_s;
  double rates_hz = s.lidar.rate_hz;
  for (const RigCamera& camera : s.cameras) rates_hz += camera.settings.rate_hz;
  const double frames = seconds * rates_hz;
  if (frames > kMaxFramesPerSession)
    r.Fail("motions", "make a session of up to " + std::to_string(static_cast<int64_t>(seconds)) + " s with " +
                          std::to_string(static_cast<int64_t>(frames)) + " camera and LiDAR frames: at most " +
                          std::to_string(static_cast<int64_t>(kMaxFramesPerSession)) + " fit in memory");
}

Scenario Read(ConfigReader r, const std::string& name) {
  Scenario s;
  s.name = name;
  r.Require("seed", &s.seed);
  r.Require("scene", &s.scene, OneOf({"indoor", "outdoor"}));
  if (s.scene == "outdoor") s.rig_position_m = Eigen::Vector3d(0.0, 0.0, 1.8);
  r.Get("start_utime", &s.start_utime, NonNegative<int64_t>());
  ReadCameras(r, &s);
  for (const char* section : {"lidar", "motions", "noise"})
    if (!r.Has(section)) r.Fail(section, "is required");
  ReadLidar(r.Child("lidar"), &s.lidar);
  ReadRig(r.Child("rig"), &s);
  ReadMotions(r.Child("motions"), &s.motions);
  ReadNoise(r.Child("noise"), &s.noise, &s.lidar);
  ReadExtrinsicChanges(r, s, &s.extrinsic_changes);
  CheckSessionLength(r, s);
  r.Finish();
  return s;
}

}  // namespace

Scenario LoadScenario(const std::string& path) {
  return Read(ConfigReader::FromFile(path), std::filesystem::path(path).stem().string());
}

Scenario ParseScenario(const std::string& yaml_text) { return Read(ConfigReader::FromString(yaml_text), "string"); }

}  // namespace fusecal::sim
