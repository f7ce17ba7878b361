// Photographic textures with mip-maps: trilinear lookups with mirrored repeat, grey and BGR, 0..255.
#pragma once

#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace fusecal::sim {

class Texture {
 public:
  // From an 8-bit BGR (or grey) photograph. Level 0 is the photo resampled to power-of-two sides (for
  // cheap mirrored addressing); its world aspect stays the photo's (see aspect()).
  static Texture FromImage(const cv::Mat& image, const std::string& name);
  // Loads dir/name with OpenCV; throws std::runtime_error when missing.
  static Texture Load(const std::string& dir, const std::string& name);

  // (s, t): texture coordinates where one copy of the photo spans [0, 1) x [0, 1); copies repeat
  // mirrored, so there are no seams. lod: log2 of the sample footprint in level-0 texels of s.
  float SampleGrey(float s, float t, float lod) const;
  void SampleBgr(float s, float t, float lod, float bgr[3]) const;

  const std::string& name() const { return name_; }
  double aspect() const { return aspect_; }        // photo height / width
  int width() const { return levels_.front().w; }  // level-0 texels along s

 private:
  struct Level {
    int w = 0, h = 0;
    std::vector<uint8_t> grey;  // w * h (8 bits: a quarter of the memory traffic of floats)
    std::vector<uint8_t> bgr;   // w * h * 3
  };
  float GreyAt(const Level& level, float s, float t) const;
  void BgrAt(const Level& level, float s, float t, float weight, float bgr[3]) const;

  std::string name_;
  double aspect_ = 1.0;
  std::vector<Level> levels_;
};

}  // namespace fusecal::sim
