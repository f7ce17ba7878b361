#include "stages/camera_frontend/node/camera_frontend_node.hpp"

#include "runtime/channels.hpp"
#include "stages/formats/conversions.hpp"
#include "stages/formats/motion_message.hpp"

namespace fusecal {

std::string CameraFrontendNodeSettings::Validate() const {
  if (previous_stations < 1 || previous_stations > 10) return "previous_stations: must be in [1, 10]";
  return frontend.Validate();
}

CameraFrontendNodeSettings ReadCameraFrontendNodeSettings(ConfigReader r) {
  CameraFrontendNodeSettings s;
  r.Get("previous_stations", &s.previous_stations);
  r.Get("max_features", &s.frontend.features.max_features);
  r.Get("detection_scale", &s.frontend.features.detection_scale);
  r.Get("ratio", &s.frontend.matching.ratio);
  r.Get("min_inliers", &s.frontend.min_inliers);
  r.Finish();
  r.FailIfInvalid(s.Validate(), {{"max_features", "features.max_features"},
                                 {"detection_scale", "features.detection_scale"},
                                 {"ratio", "matching.ratio"}});
  return s;
}

CameraFrontendNode::CameraFrontendNode(CameraFrontendNodeSettings settings)
    : StationPairNode<StationFeatures>("camera", ForCamera(channels::kStation, settings.camera),
                                       ForCamera(channels::kCameraMotion, settings.camera), settings.previous_stations),
      settings_(std::move(settings)) {}

StationFeatures CameraFrontendNode::Prepare(const station_t& station) {
  StationFeatures prepared;
  prepared.camera = MakeCameraModel(CameraFromMsg(station.camera));
  const cv::Mat image = ImageToMat(station.image);
  prepared.features = ExtractImageFeatures(image, *prepared.camera, settings_.frontend.features);
  return prepared;
}

motion_t CameraFrontendNode::Pair(int previous_id, const StationFeatures& previous, const station_t& station,
                                  const StationFeatures& current) {
  const RelativePoseResult result =
      EstimateRelativePose(previous.features, current.features, *current.camera, settings_.frontend);
  motion_t motion =
      result.usable()
          ? MakeMotion(previous_id, station.id, "camera", result.A(), false, result.covariance, station.utime)
          : MakeFailedMotion(previous_id, station.id, "camera", result.failure_reason.text, station.utime);
  motion.inliers = result.inliers;
  motion.rmse = result.median_epipolar_error_deg;
  motion.iterations = result.refinement_iterations;
  motion.seconds = result.seconds;
  return motion;
}

}  // namespace fusecal
