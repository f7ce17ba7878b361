// A minimal stage for testing StageMain: counts PROBE_IN messages, answers on PROBE_OUT, throws on
// PROBE_THROW. Config key: `reply_prefix` (string).
#include "runtime/config_reader.hpp"
#include "runtime/stage_main.hpp"

namespace {

class ProbeNode : public fusecal::StageNode {
 public:
  explicit ProbeNode(std::string prefix) : prefix_(std::move(prefix)) {}
  void Start(fusecal::Bus& bus) override {
    subs_.push_back(bus.SubscribeRaw("PROBE_IN", [this, &bus](const fusecal::RawMessage& m) {
      ++received_;
      const std::string reply = prefix_ + std::string(reinterpret_cast<const char*>(m.data), m.size);
      bus.PublishRaw("PROBE_OUT", reply.data(), reply.size());
    }));
    subs_.push_back(bus.SubscribeRaw(
        "PROBE_THROW", [](const fusecal::RawMessage&) { throw std::runtime_error("probe asked to fail"); }));
  }
  fusecal::StageStatus Status() const override {
    fusecal::StageStatus s;
    s.counters["received"] = received_;
    return s;
  }

 private:
  std::string prefix_;
  int received_ = 0;
  std::vector<fusecal::Subscription> subs_;
};

}  // namespace

int main(int argc, char** argv) {
  fusecal::StageDefinition stage;
  stage.name = "probe";
  stage.description = "test probe stage";
  stage.make_node = [](const std::string& config_path, const std::string&) {
    std::string prefix = "echo:";
    if (!config_path.empty()) {
      auto config = fusecal::ConfigReader::FromFile(config_path);
      config.Get("reply_prefix", &prefix);
      config.Finish();
    }
    return std::make_unique<ProbeNode>(prefix);
  };
  return fusecal::StageMain(argc, argv, stage);
}
