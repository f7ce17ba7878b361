// Conversions between lcmtypes and the types the stage cores use (OpenCV, Eigen, PointCloud).
// This is the only place where the two meet. Every function checks its input and throws
// ConversionError with a message that says what is wrong.
#pragma once

#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>

#include "fusecal/camera_info_t.hpp"
#include "fusecal/image_t.hpp"
#include "fusecal/point_cloud_t.hpp"
#include "stages/foundation/camera_model.hpp"
#include "stages/foundation/point_cloud.hpp"
#include "stages/foundation/se3.hpp"

namespace fusecal {

class ConversionError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Image encodings carried by image_t.
bool IsKnownImageEncoding(const std::string& encoding);

// Decodes an image message to an 8-bit cv::Mat: CV_8UC1 for mono8, CV_8UC3 in BGR order for colour
// (rgb8 is reordered), and whatever the file holds (grey or BGR) for jpeg/png; jpeg/png data must be of
// that format (checked in its header) and at most 8192x8192 pixels.
cv::Mat ImageToMat(const image_t& msg);
// The utime of an LCM-encoded fusecal message without decoding it: every fusecal type begins with
// `int64_t utime`, right after LCM's 8-byte fingerprint (big-endian). -1 when the buffer is too short.
int64_t PeekUtime(const uint8_t* data, size_t size);

// A quick grey decode for measuring motion: JPEG decoded at the coarsest scale (1/2, 1/4, 1/8, which
// libjpeg does in the DCT domain) that is still at least `min_width` wide; other encodings as ImageToMat.
// Throws ConversionError as ImageToMat does.
cv::Mat ImageToMatReduced(const image_t& msg, int min_width);

// Encodes an 8-bit grey or BGR image. encoding: mono8, rgb8, bgr8, jpeg or png. Grey images are
// expanded for rgb8/bgr8; colour images are converted to grey for mono8.
image_t MatToImage(const cv::Mat& image, const std::string& encoding, int64_t utime,
                   const std::string& frame_id = "camera");

PointCloud CloudFromMsg(const point_cloud_t& msg);
point_cloud_t CloudToMsg(const PointCloud& cloud, int64_t utime, const std::string& frame_id = "lidar");

CameraParams CameraFromMsg(const camera_info_t& msg);
camera_info_t CameraToMsg(const CameraParams& params, int64_t utime = 0);

// 6x6 matrices travel row-major in 36 doubles.
void Matrix6ToArray(const Matrix6& m, double out[36]);
Matrix6 Matrix6FromArray(const double in[36]);

}  // namespace fusecal
