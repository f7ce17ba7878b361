#include "formats/extrinsic_status.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <utility>

namespace fusecal {

namespace {

constexpr std::array<std::pair<int8_t, const char*>, 6> kStatusNames{{
    {extrinsic_t::STATUS_INITIAL, "initial"},
    {extrinsic_t::STATUS_REFINING, "refining"},
    {extrinsic_t::STATUS_CONVERGED, "converged"},
    {extrinsic_t::STATUS_NOT_CONVERGED, "not_converged"},
    {extrinsic_t::STATUS_DEGENERATE, "degenerate"},
    {extrinsic_t::STATUS_FAILED, "failed"},
}};

constexpr std::array<std::pair<int8_t, const char*>, 4> kObservabilityNames{{
    {extrinsic_t::OBSERVABILITY_OK, "ok"},
    {extrinsic_t::OBSERVABILITY_ROTATION_DEGENERATE, "rotation_degenerate"},
    {extrinsic_t::OBSERVABILITY_TRANSLATION_PARTLY_UNOBSERVABLE, "translation_partly_unobservable"},
    {extrinsic_t::OBSERVABILITY_TOO_FEW_MOTIONS, "too_few_motions"},
}};

template <size_t N>
const char* NameOf(const std::array<std::pair<int8_t, const char*>, N>& names, int8_t value) {
  for (const auto& [v, name] : names)
    if (v == value) return name;
  return "unknown";
}

template <size_t N>
int8_t ValueOf(const std::array<std::pair<int8_t, const char*>, N>& names, const std::string& name,
               const char* what) {
  for (const auto& [v, n] : names)
    if (name == n) return v;
  throw std::invalid_argument(std::string("unknown extrinsic ") + what + " '" + name + "'");
}

}  // namespace

const char* ExtrinsicStatusName(int8_t status) { return NameOf(kStatusNames, status); }
const char* ObservabilityName(int8_t observability) { return NameOf(kObservabilityNames, observability); }
int8_t ExtrinsicStatusFromName(const std::string& name) { return ValueOf(kStatusNames, name, "status"); }
int8_t ObservabilityFromName(const std::string& name) {
  return ValueOf(kObservabilityNames, name, "observability");
}

bool UsesMotionTo(const extrinsic_t& e, int station_j) {
  return std::find(e.used_station_j.begin(), e.used_station_j.end(), station_j) != e.used_station_j.end();
}

bool TookMotionTo(const extrinsic_t& e, int station_j) {
  return UsesMotionTo(e, station_j) ||
         std::find(e.rejected_station_j.begin(), e.rejected_station_j.end(), station_j) != e.rejected_station_j.end();
}

}  // namespace fusecal
