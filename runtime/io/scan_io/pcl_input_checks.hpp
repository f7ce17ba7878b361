// Checks of .pcd and .ply files before PCL reads them (scan_io.cpp). PCL's readers trust their input:
// found by fuzzing (tests/fuzz, tools/fuzz), a few bytes made them allocate terabytes or abort:
//   - PCD: PCL keeps parsing header lines after DATA, so binary data that starts with "COLUMNS" or
//     "POINTS ..." rewrites the header (and its POINTS line resizes the data to its count);
//   - PCD: WIDTH x HEIGHT overflowed, and a binary_compressed size larger than LZF can expand was
//     allocated;
//   - PLY: a list property in the vertex element hits an assert in PCL's PLYReader; element counts are
//     allocated before the data is read.
// Internal to fusecal_scan_io.
#pragma once

#include <cstddef>
#include <string>

namespace fusecal::scan_checks {

// Known keys, consistent FIELDS/SIZE/TYPE/COUNT, WIDTH x HEIGHT = POINTS (at most 2^32 - 1 each), data
// long enough for every point, nothing after DATA that PCL would take for a header line. Returns the
// number of points; throws std::runtime_error naming the file and the problem.
size_t CheckPcd(const std::string& path);

// "ply", a known format, comment/obj_info/element/property lines up to end_header; a vertex element of
// scalar properties only; every element with a property and no more instances than bytes after the
// header (binary: the vertices fit). Returns the number of vertices; throws as CheckPcd.
size_t CheckPly(const std::string& path);

}  // namespace fusecal::scan_checks
