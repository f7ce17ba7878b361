#include "runtime/rig.hpp"

#include <algorithm>
#include <cctype>

namespace fusecal {

bool Rig::Has(const std::string& name) const {
  return std::find(cameras.begin(), cameras.end(), name) != cameras.end();
}

std::string CameraNameProblem(const std::string& name) {
  if (name.empty() || name.size() > 32) return "must have 1 to 32 characters";
  if (!std::isalpha(static_cast<unsigned char>(name.front()))) return "must start with a letter";
  for (const char c : name)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_')
      return "may hold only letters, digits and _ (it ends the camera's channel names)";
  return "";
}

std::vector<std::string> ReadRigCameras(ConfigReader& root) {
  if (!root.Has("cameras")) {
    root.Items("cameras");  // marks the key read
    return {""};
  }
  std::vector<std::string> names;
  std::vector<ConfigReader> items = root.Items("cameras");
  if (items.empty()) root.Fail("cameras", "must name at least one camera (or be left out for one camera)");
  if (static_cast<int>(items.size()) > kMaxCameras)
    root.Fail("cameras", "at most " + std::to_string(kMaxCameras) + " cameras");
  for (auto& item : items) {
    std::string name;
    item.Require<std::string>("name", &name, CameraNameProblem);
    item.Finish();
    if (std::find(names.begin(), names.end(), name) != names.end())
      item.Fail("name", "'" + name + "' names two cameras");
    names.push_back(name);
  }
  return names;
}

}  // namespace fusecal
