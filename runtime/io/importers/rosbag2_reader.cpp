#include "runtime/io/importers/rosbag2_reader.hpp"

#include <yaml-cpp/yaml.h>

#include <filesystem>
#include <map>
#include <queue>
#include <stdexcept>
#include <utility>

#include "runtime/io/importers/rosbag2_storage.hpp"

namespace fusecal {

namespace {

namespace fs = std::filesystem;
using rosbag2_detail::MessageCursor;
using rosbag2_detail::StorageFile;
using rosbag2_detail::StoredMessage;
using rosbag2_detail::StoredTopic;

bool HasExtension(const fs::path& path, const char* extension) { return path.extension() == extension; }

// What metadata.yaml says: the files in recording order and the topics with their counts.
struct BagLayout {
  std::vector<fs::path> files;
  std::string storage_identifier;  // "mcap" or "sqlite3"
  std::vector<Rosbag2Topic> topics;
};

// A listed path is relative to the bag folder; early rosbag2 versions wrote it with the folder's own name
// in front, so a path not found as given is looked up by its file name.
fs::path ResolveListed(const fs::path& folder, const std::string& listed) {
  const fs::path direct = folder / listed;
  std::error_code error;
  if (fs::exists(direct, error)) return direct;
  const fs::path by_name = folder / fs::path(listed).filename();
  if (fs::exists(by_name, error)) return by_name;
  throw std::runtime_error((folder / "metadata.yaml").string() + ": lists " + listed + ", which is not in " +
                           folder.string());
}

BagLayout ParseMetadata(const fs::path& folder, const YAML::Node& root) {
  const YAML::Node info = root["rosbag2_bagfile_information"];
  if (!info.IsMap()) throw std::runtime_error("no rosbag2_bagfile_information map");
  // Whole files or single messages compressed by rosbag2 (not MCAP's own chunk compression).
  const std::string compression = info["compression_mode"] ? info["compression_mode"].as<std::string>() : "";
  if (!compression.empty() && compression != "NONE")
    throw std::runtime_error("the bag is compressed by rosbag2 (compression_mode " + compression +
                             "), which is not read; `ros2 bag convert` writes an uncompressed copy");
  BagLayout layout;
  if (info["storage_identifier"]) layout.storage_identifier = info["storage_identifier"].as<std::string>();
  for (const YAML::Node& listed : info["relative_file_paths"])
    layout.files.push_back(ResolveListed(folder, listed.as<std::string>()));
  if (layout.files.empty()) throw std::runtime_error("relative_file_paths lists no file");
  for (const YAML::Node& entry : info["topics_with_message_count"]) {
    const YAML::Node topic = entry["topic_metadata"];
    Rosbag2Topic t;
    t.name = topic["name"].as<std::string>();
    t.type = topic["type"].as<std::string>("");
    t.serialization_format = topic["serialization_format"].as<std::string>("");
    t.message_count = entry["message_count"].as<uint64_t>(0);
    layout.topics.push_back(std::move(t));
  }
  return layout;
}

BagLayout ReadMetadata(const fs::path& folder) {
  const fs::path file = folder / "metadata.yaml";
  try {
    return ParseMetadata(folder, YAML::LoadFile(file.string()));
  } catch (const YAML::Exception& e) {
    throw std::runtime_error(file.string() + ": " + e.what());
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    // Errors that already name a file keep their words; the others get this file's name.
    if (what.rfind(file.string(), 0) == 0) throw;
    throw std::runtime_error(file.string() + ": " + what);
  }
}

std::unique_ptr<StorageFile> OpenStorage(const fs::path& file, const std::string& storage_identifier, bool count) {
  if (HasExtension(file, ".mcap") || (!HasExtension(file, ".db3") && storage_identifier == "mcap"))
    return rosbag2_detail::OpenMcapStorage(file.string());
  if (HasExtension(file, ".db3") || storage_identifier == "sqlite3")
    return rosbag2_detail::OpenDb3Storage(file.string(), count);
  throw std::runtime_error(file.string() + ": neither .mcap nor .db3, and the storage '" + storage_identifier +
                           "' is not read");
}

}  // namespace

bool Rosbag2Reader::IsRosbag2(const std::string& path) {
  std::error_code error;
  if (fs::is_directory(path, error)) return fs::is_regular_file(fs::path(path) / "metadata.yaml", error);
  return fs::is_regular_file(path, error) && (HasExtension(path, ".mcap") || HasExtension(path, ".db3"));
}

Rosbag2Reader::Rosbag2Reader(const std::string& path) : path_(path) {
  std::error_code error;
  if (fs::is_directory(path, error)) {
    if (!fs::is_regular_file(fs::path(path) / "metadata.yaml", error))
      throw std::runtime_error(path +
                               ": a folder without metadata.yaml is no rosbag2 bag (`ros2 bag reindex` "
                               "writes one)");
    BagLayout layout = ReadMetadata(path);
    topics_ = std::move(layout.topics);
    for (const fs::path& file : layout.files) files_.push_back(OpenStorage(file, layout.storage_identifier, false));
  } else if (IsRosbag2(path)) {
    files_.push_back(OpenStorage(path, "", true));
  } else {
    throw std::runtime_error(path + ": not a rosbag2 bag (a folder with metadata.yaml, an .mcap or a .db3 file)");
  }
  MergeTopics();
}

Rosbag2Reader::~Rosbag2Reader() = default;

// Topics by name over all files. metadata.yaml's counts stand; a topic it does not list is counted from
// the files.
void Rosbag2Reader::MergeTopics() {
  std::map<std::string, size_t> by_name;
  for (size_t i = 0; i < topics_.size(); ++i) by_name.emplace(topics_[i].name, i);
  const size_t listed = topics_.size();
  for (const auto& file : files_) {
    std::vector<size_t>& mapping = file_topics_.emplace_back();
    for (const StoredTopic& topic : file->topics()) {
      const auto [it, added] = by_name.emplace(topic.name, topics_.size());
      if (added) topics_.push_back({topic.name, topic.type, topic.serialization_format, 0});
      Rosbag2Topic& merged = topics_[it->second];
      if (it->second >= listed) merged.message_count += topic.message_count;
      if (merged.type.empty()) merged.type = topic.type;
      if (!topic.type.empty() && topic.type != merged.type)
        warnings_.push_back(path_ + ": topic " + topic.name + " has type " + topic.type + " in one file and " +
                            merged.type + " elsewhere; its messages are all given as " + merged.type);
      mapping.push_back(it->second);
    }
    for (std::string& warning : file->warnings()) warnings_.push_back(std::move(warning));
  }
}

const std::vector<Rosbag2Topic>& Rosbag2Reader::topics() const { return topics_; }
const std::vector<std::string>& Rosbag2Reader::warnings() const { return warnings_; }

uint64_t Rosbag2Reader::bytes_read() const {
  uint64_t total = 0;
  for (const auto& file : files_) total += file->bytes_read();
  return total;
}

// A k-way merge of the files' cursors (each in log-time order) on (log time, file): split files mostly
// follow each other, but nothing stops them from overlapping.
void Rosbag2Reader::ForEach(const std::set<std::string>& topic_names,
                            const std::function<void(const Rosbag2Message&)>& visit) {
  std::vector<bool> wanted(topics_.size(), topic_names.empty());
  for (size_t i = 0; i < topics_.size(); ++i)
    if (topic_names.count(topics_[i].name)) wanted[i] = true;
  std::vector<std::unique_ptr<MessageCursor>> cursors(files_.size());
  std::vector<StoredMessage> current(files_.size());
  using Head = std::pair<int64_t, size_t>;  // log time, file
  std::priority_queue<Head, std::vector<Head>, std::greater<Head>> heads;
  for (size_t f = 0; f < files_.size(); ++f) {
    std::vector<bool> local(file_topics_[f].size());
    bool any = false;
    for (size_t t = 0; t < local.size(); ++t) any |= (local[t] = wanted[file_topics_[f][t]]);
    if (!any) continue;
    cursors[f] = files_[f]->Messages(local);
    if (cursors[f]->Next(current[f])) heads.emplace(current[f].log_time_ns, f);
  }
  while (!heads.empty()) {
    const size_t f = heads.top().second;
    heads.pop();
    const StoredMessage& m = current[f];
    visit(Rosbag2Message{&topics_[file_topics_[f][m.topic]], m.log_time_ns, m.data, m.size});
    if (cursors[f]->Next(current[f])) heads.emplace(current[f].log_time_ns, f);
  }
}

}  // namespace fusecal
