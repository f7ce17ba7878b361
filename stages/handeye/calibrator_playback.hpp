// Playing motion pairs through the calibration loop as the pipeline would (tests and benchmarks): for each
// pair its LiDAR motion, then its camera motion as the front end gives it (translation a direction), and
// every request answered at once with the metric camera motions of the pairs it lists, as fusion odometry
// would.
#pragma once

#include <functional>
#include <vector>

#include "stages/handeye/calibrator.hpp"

namespace fusecal {

// What fusion odometry answers for `pair` to the request `request`: its metric camera motion, which a test
// may make miss as fusion odometry would at the request's estimate.
using FusedAnswer = std::function<Isometry3(const CalibrationVersion& request, const MotionPair& pair)>;

// Pairs [from, to) of `pairs` (to < 0: to the end); `pairs` holds the metric camera motions A of every pair
// a request may list (answered as they are, or as `answer` makes them).
void PlayMetricPairs(Calibrator& calibrator, const std::vector<MotionPair>& pairs, int from = 0, int to = -1,
                     const FusedAnswer& answer = {});

}  // namespace fusecal
