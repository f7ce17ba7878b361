// Googletest expectations on point clouds, shared by the tests of the formats and the importers.
#pragma once

#include <gtest/gtest.h>

#include "stages/foundation/point_cloud.hpp"

namespace fusecal::testing {

// The same points, intensities and rings, and time offsets within a microsecond.
inline void ExpectSameCloud(const PointCloud& got, const PointCloud& want) {
  EXPECT_EQ(got.points, want.points);
  EXPECT_EQ(got.intensity, want.intensity);
  EXPECT_EQ(got.ring, want.ring);
  ASSERT_EQ(got.time_offset_s.size(), want.time_offset_s.size());
  for (size_t i = 0; i < got.time_offset_s.size(); ++i) EXPECT_NEAR(got.time_offset_s[i], want.time_offset_s[i], 1e-6);
}

}  // namespace fusecal::testing
