#include "runtime/sim/simulator/texture.hpp"

#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusecal::sim {

namespace {

int CeilPow2(int n, int cap) {
  int p = 1;
  while (p < n && p < cap) p *= 2;
  return p;
}

// Texels i and i + 1 of a mirrored repeat of n texels (n a power of two).
inline void MirrorPair(int i, int n, int* a, int* b) {
  const int p = i & (2 * n - 1);
  if (p < n) {
    *a = p;
    *b = p + 1 < n ? p + 1 : n - 1;
  } else {
    *a = 2 * n - 1 - p;
    *b = *a > 0 ? *a - 1 : 0;
  }
}

struct Bilinear {
  int x0, x1, y0, y1;
  float ax, ay;
};

// floor for |x| < 2^31 without a library call (baseline x86-64 has no rounding instruction).
inline int FloorInt(float x) {
  const int i = static_cast<int>(x);
  return i - (x < static_cast<float>(i));
}

inline Bilinear Setup(float s, float t, int w, int h) {
  const float x = s * w - 0.5f, y = t * h - 0.5f;
  const int ix = FloorInt(x), iy = FloorInt(y);
  Bilinear b;
  b.ax = x - static_cast<float>(ix);
  b.ay = y - static_cast<float>(iy);
  MirrorPair(ix, w, &b.x0, &b.x1);
  MirrorPair(iy, h, &b.y0, &b.y1);
  return b;
}

}  // namespace

Texture Texture::FromImage(const cv::Mat& image, const std::string& name) {
  if (image.empty() || image.depth() != CV_8U) throw std::runtime_error("texture " + name + ": not an 8-bit image");
  cv::Mat bgr;
  if (image.channels() == 1)
    cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
  else
    bgr = image;
  Texture tex;
  tex.name_ = name;
  tex.aspect_ = static_cast<double>(bgr.rows) / bgr.cols;
  cv::Mat level;  // 8-bit BGR, continuous
  const cv::Size size0(CeilPow2(bgr.cols, 1024), CeilPow2(bgr.rows, 1024));
  cv::resize(bgr, level, size0, 0, 0, size0.area() >= bgr.size().area() ? cv::INTER_CUBIC : cv::INTER_AREA);
  while (true) {
    cv::Mat grey;
    cv::cvtColor(level, grey, cv::COLOR_BGR2GRAY);
    Level l;
    l.w = level.cols;
    l.h = level.rows;
    l.bgr.assign(level.ptr<uint8_t>(), level.ptr<uint8_t>() + l.w * l.h * 3);
    l.grey.assign(grey.ptr<uint8_t>(), grey.ptr<uint8_t>() + l.w * l.h);
    tex.levels_.push_back(std::move(l));
    if (level.cols <= 4 || level.rows <= 4) break;
    cv::Mat half;
    cv::resize(level, half, cv::Size(level.cols / 2, level.rows / 2), 0, 0, cv::INTER_AREA);
    level = half;
  }
  return tex;
}

Texture Texture::Load(const std::string& dir, const std::string& name) {
  const std::string path = dir + "/" + name;
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  if (image.empty()) throw std::runtime_error("cannot read texture " + path);
  return FromImage(image, name);
}

float Texture::GreyAt(const Level& l, float s, float t) const {
  const Bilinear b = Setup(s, t, l.w, l.h);
  const uint8_t* r0 = l.grey.data() + b.y0 * l.w;
  const uint8_t* r1 = l.grey.data() + b.y1 * l.w;
  const float a00 = r0[b.x0], a01 = r0[b.x1], a10 = r1[b.x0], a11 = r1[b.x1];
  const float top = a00 + b.ax * (a01 - a00);
  const float bottom = a10 + b.ax * (a11 - a10);
  return top + b.ay * (bottom - top);
}

void Texture::BgrAt(const Level& l, float s, float t, float weight, float bgr[3]) const {
  const Bilinear b = Setup(s, t, l.w, l.h);
  const float w00 = (1 - b.ax) * (1 - b.ay) * weight, w01 = b.ax * (1 - b.ay) * weight;
  const float w10 = (1 - b.ax) * b.ay * weight, w11 = b.ax * b.ay * weight;
  const uint8_t* p00 = l.bgr.data() + 3 * (b.y0 * l.w + b.x0);
  const uint8_t* p01 = l.bgr.data() + 3 * (b.y0 * l.w + b.x1);
  const uint8_t* p10 = l.bgr.data() + 3 * (b.y1 * l.w + b.x0);
  const uint8_t* p11 = l.bgr.data() + 3 * (b.y1 * l.w + b.x1);
  for (int c = 0; c < 3; ++c) bgr[c] += w00 * p00[c] + w01 * p01[c] + w10 * p10[c] + w11 * p11[c];
}

float Texture::SampleGrey(float s, float t, float lod) const {
  const int last = static_cast<int>(levels_.size()) - 1;
  if (!(lod > 0.0f)) return GreyAt(levels_[0], s, t);
  if (lod >= last) return GreyAt(levels_[last], s, t);
  const int level = static_cast<int>(lod);
  const float f = lod - level;
  const float a = GreyAt(levels_[level], s, t);
  return a + f * (GreyAt(levels_[level + 1], s, t) - a);
}

void Texture::SampleBgr(float s, float t, float lod, float bgr[3]) const {
  bgr[0] = bgr[1] = bgr[2] = 0.0f;
  const int last = static_cast<int>(levels_.size()) - 1;
  if (!(lod > 0.0f)) return BgrAt(levels_[0], s, t, 1.0f, bgr);
  if (lod >= last) return BgrAt(levels_[last], s, t, 1.0f, bgr);
  const int level = static_cast<int>(lod);
  const float f = lod - level;
  BgrAt(levels_[level], s, t, 1.0f - f, bgr);
  BgrAt(levels_[level + 1], s, t, f, bgr);
}

}  // namespace fusecal::sim
