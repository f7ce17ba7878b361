// Camera motions with one unknown scale for the whole trajectory (structure from motion, monocular SLAM):
// the camera translations are metric up to a factor lambda, the same for every motion:
//   R_a t + lambda t_a = R t_b + t     (the paper's translation equation with s_i = lambda for all i)
#pragma once

#include <vector>

#include "stages/handeye/handeye_types.hpp"

namespace fusecal {

// 1. SolveScaleless: the rotation, the screening and outliers (one scale per motion).
// 2. t and lambda by linear least squares over the pairs it used:  [(R_a - I)  t_a] [t; lambda] = R t_b.
// 3. The camera translations times lambda are metric: SolveScaled refines R and t together from there.
// The result's `scales` holds lambda alone and `scale_std_devs` its standard deviation (from step 2, at
// the residuals' noise). Failed (with the reason) when lambda is not determined or not positive.
HandEyeResult SolveGlobalScale(const std::vector<MotionPair>& pairs, const HandEyeSettings& settings = {});

}  // namespace fusecal
