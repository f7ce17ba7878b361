// Benchmark (not a test): time and accuracy of one registration of two ~120k-point scans, ours (no
// guess) against PCL's pcl::GeneralizedIterativeClosestPoint with its default settings from identity,
// in the same run, on a KITTI pair (when the snippet is present) and synthetic HDL-64E-like room pairs.
//
//   bench_lidar_icp [--repeat N] [--pcl-voxel M] [--no-pcl] [--kitti DIR]
//
// --pcl-voxel M also runs PCL GICP on clouds voxel-downsampled to M metres (pcl::VoxelGrid), as a fairer
// comparison than the raw clouds. Accuracy: against the true motion for synthetic pairs; for KITTI (no
// ground truth) against our result, plus an alignment score of each result (share of raw source points
// within 0.1 m of a raw target point, and their RMS distance).
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/registration/gicp.h>
#include <sys/resource.h>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "runtime/io/scan_io/scan_io.hpp"
#include "runtime/sim/fixtures/synthetic_scans.hpp"
#include "stages/foundation/se3.hpp"
#include "stages/lidar_icp/registration.hpp"

namespace {

using fusecal::Isometry3;
using fusecal::PointCloud;
using Cloud = pcl::PointCloud<pcl::PointXYZ>;

double CpuSeconds() {
  rusage u;
  getrusage(RUSAGE_SELF, &u);
  return u.ru_utime.tv_sec + u.ru_stime.tv_sec + 1e-6 * (u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

double Now() { return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count(); }

Cloud::Ptr ToPcl(const PointCloud& scan) {
  Cloud::Ptr c(new Cloud);
  for (const Eigen::Vector3f& p : scan.points)
    if (p.allFinite()) c->push_back(pcl::PointXYZ(p.x(), p.y(), p.z()));
  return c;
}

Cloud::Ptr Voxel(const Cloud::Ptr& in, double m) {
  Cloud::Ptr out(new Cloud);
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setInputCloud(in);
  grid.setLeafSize(m, m, m);
  grid.filter(*out);
  return out;
}

// Share of source points within 0.1 m of a target point after T, and the RMS of those distances.
void Alignment(const Cloud::Ptr& target, const pcl::KdTreeFLANN<pcl::PointXYZ>& tree, const Cloud::Ptr& source,
               const Isometry3& T, double* ratio, double* rms) {
  size_t hits = 0, n = 0;
  double sum = 0;
  std::vector<int> idx(1);
  std::vector<float> d2(1);
  const Eigen::Isometry3f Tf = T.cast<float>();
  for (size_t i = 0; i < source->size(); i += 4, ++n) {
    const Eigen::Vector3f q = Tf * (*source)[i].getVector3fMap();
    if (tree.nearestKSearch(pcl::PointXYZ(q.x(), q.y(), q.z()), 1, idx, d2) == 1 && d2[0] < 0.01f) {
      ++hits;
      sum += d2[0];
    }
  }
  *ratio = n ? double(hits) / n : 0;
  *rms = hits ? std::sqrt(sum / hits) : 0;
}

struct Row {
  std::string method;
  Isometry3 T;
  bool ok;
  double wall, cpu;
};

void Report(const char* pair, const std::vector<Row>& rows, const Isometry3* truth, const Cloud::Ptr& target,
            const Cloud::Ptr& source) {
  pcl::KdTreeFLANN<pcl::PointXYZ> tree;
  tree.setInputCloud(target);
  const Isometry3& reference = truth ? *truth : rows.front().T;
  std::printf("\n%s (%zu / %zu points)%s\n", pair, target->size(), source->size(),
              truth ? "" : "  [no ground truth: errors are relative to ours]");
  std::printf("  %-28s %6s %9s %9s %12s %12s %10s %9s\n", "method", "ok", "wall s", "cpu s", "rot err deg",
              "trans err mm", "within 0.1", "rms mm");
  for (const Row& r : rows) {
    double ratio, rms;
    Alignment(target, tree, source, r.T, &ratio, &rms);
    std::printf("  %-28s %6s %9.3f %9.3f %12.4f %12.2f %10.3f %9.1f\n", r.method.c_str(), r.ok ? "yes" : "no", r.wall,
                r.cpu, fusecal::RotationErrorDeg(r.T.linear(), reference.linear()),
                1e3 * (r.T.translation() - reference.translation()).norm(), ratio, 1e3 * rms);
  }
}

std::vector<Row> RunAll(const PointCloud& scan_i, const PointCloud& scan_j, int repeat, bool pcl, double pcl_voxel) {
  std::vector<Row> rows;
  for (int threads : {1, 0}) {
    fusecal::lidar_icp::RegistrationSettings settings;
    settings.num_threads = threads;
    fusecal::lidar_icp::RegistrationResult best;
    double wall = 1e9, cpu = 1e9;
    for (int k = 0; k < repeat; ++k) {
      const double w0 = Now(), c0 = CpuSeconds();
      best = fusecal::lidar_icp::Register(scan_i, scan_j, settings);
      wall = std::min(wall, Now() - w0);
      cpu = std::min(cpu, CpuSeconds() - c0);
    }
    if (!best.usable()) std::printf("  ours failed: %s\n", best.failure_reason.text.c_str());
    rows.push_back({threads == 0 ? "ours (no guess), all cores" : "ours (no guess), 1 thread", best.T_li_lj,
                    best.usable(), wall, cpu});
  }
  if (!pcl) return rows;
  auto run_pcl = [&](const std::string& name, const Cloud::Ptr& target, const Cloud::Ptr& source) {
    pcl::GeneralizedIterativeClosestPoint<pcl::PointXYZ, pcl::PointXYZ> gicp;  // defaults
    gicp.setInputTarget(target);
    gicp.setInputSource(source);
    Cloud aligned;
    const double w0 = Now(), c0 = CpuSeconds();
    gicp.align(aligned);  // from identity
    Isometry3 T = Isometry3::Identity();
    T.matrix() = gicp.getFinalTransformation().cast<double>();
    rows.push_back({name, T, gicp.hasConverged(), Now() - w0, CpuSeconds() - c0});
  };
  const Cloud::Ptr target = ToPcl(scan_i), source = ToPcl(scan_j);
  run_pcl("PCL GICP default, raw", target, source);
  if (pcl_voxel > 0) {
    char name[64];
    std::snprintf(name, sizeof(name), "PCL GICP default, voxel %.2f", pcl_voxel);
    run_pcl(name, Voxel(target, pcl_voxel), Voxel(source, pcl_voxel));
  }
  return rows;
}

}  // namespace

int main(int argc, char** argv) {
  int repeat = 3;
  bool pcl = true;
  double pcl_voxel = 0.0;
  std::string kitti = KITTI_SNIPPET_DIR;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--repeat" && i + 1 < argc)
      repeat = std::max(1, std::atoi(argv[++i]));
    else if (a == "--pcl-voxel" && i + 1 < argc)
      pcl_voxel = std::atof(argv[++i]);
    else if (a == "--no-pcl")
      pcl = false;
    else if (a == "--kitti" && i + 1 < argc)
      kitti = argv[++i];
    else {
      std::fprintf(stderr, "usage: %s [--repeat N] [--pcl-voxel M] [--no-pcl] [--kitti DIR]\n", argv[0]);
      return 2;
    }
  }
  auto load = [] {
    std::ifstream f("/proc/loadavg");
    std::string a, b, c;
    f >> a >> b >> c;
    return a + " " + b + " " + c;
  };
  std::printf("load average at start: %s\n", load().c_str());
  std::printf(
      "bench_lidar_icp: ours = fusecal::lidar_icp::Register (best wall time of %d runs), PCL GICP once; "
      "%u hardware threads\n",
      repeat, std::thread::hardware_concurrency());

  const std::string f0 = kitti + "/velodyne_points/data/0000000000.bin";
  const std::string f2 = kitti + "/velodyne_points/data/0000000002.bin";
  if (std::filesystem::exists(f0) && std::filesystem::exists(f2)) {
    const PointCloud a = fusecal::ReadScan(f0), b = fusecal::ReadScan(f2);
    Report("KITTI 2011-09-26 frames 0 <- 2", RunAll(a, b, repeat, pcl, pcl_voxel), nullptr, ToPcl(a), ToPcl(b));
  } else {
    std::printf("\nKITTI snippet not found at %s: KITTI pair skipped\n", kitti.c_str());
  }

  const fusecal::fixtures::Scene room = fusecal::fixtures::MakeRoom();
  struct Motion {
    const char* name;
    double yaw, pitch;
    Eigen::Vector3d t;
  } motions[] = {{"synthetic room, yaw 5 deg, 0.22 m", 5, 0, {0.2, 0.1, 0.0}},
                 {"synthetic room, yaw 170 + pitch 30 deg", 170, 30, {0.3, -0.4, 0.1}}};
  for (const Motion& m : motions) {
    const Isometry3 B =
        fusecal::MakeIsometry(fusecal::RotationFromRpy(0, m.pitch * M_PI / 180, m.yaw * M_PI / 180), m.t);
    const PointCloud a =
        fusecal::fixtures::SimulateScan(room, Isometry3::Identity(), fusecal::fixtures::Hdl64Pattern(), 0.015, 1);
    const PointCloud b = fusecal::fixtures::SimulateScan(room, B, fusecal::fixtures::Hdl64Pattern(), 0.015, 2);
    Report(m.name, RunAll(a, b, repeat, pcl, pcl_voxel), &B, ToPcl(a), ToPcl(b));
  }
  std::printf("\nload average at end: %s\n", load().c_str());
  return 0;
}
