// Non-repetitive scan patterns of solid-state LiDARs: the direction of every point of a frame, which
// differs from frame to frame so that coverage of the field of view fills in over time.
//   rosette (Avia-like): each laser line is steered by two Risley prisms turning in opposite senses at
//     incommensurate rates; the angular offset from the optical axis (LiDAR x) is the sum of two circles,
//     a rosette whose petals all pass through the centre, scaled to the field of view's ellipse;
//   petal (Mid-360-like): the lines sweep the azimuth once per frame while the elevation swings between
//     the bottom and the top of the field of view at a rate that is not a multiple of the frame rate, so
//     each frame draws the zigzag at other azimuths.
// Lines fire together: column c of a frame is the instant c / (columns * rate_hz) after the frame's start,
// row l its line l.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace fusecal::sim {

struct LidarParams;

// The row-major lines x columns unit directions (LiDAR frame) of frame `frame_index`.
std::vector<Eigen::Vector3f> PatternDirections(const LidarParams& params, int frame_index);

}  // namespace fusecal::sim
