#include <gtest/gtest.h>

#include <chrono>

#include <map>
#include <string>

#include "runtime/bus_url.hpp"
#include "runtime/config_reader.hpp"
#include "runtime/strict_yaml.hpp"

namespace fusecal {
namespace {

struct Settings {
  double max_range_m = 100;
  int beams = 64;
  std::string model = "multibeam";
};

Settings Load(const std::string& text) {
  Settings s;
  ConfigReader r = ConfigReader::FromString(text);
  ConfigReader lidar = r.Child("lidar");
  lidar.Get("max_range_m", &s.max_range_m, Positive<double>());
  lidar.Get("beams", &s.beams, InRange(1, 128));
  lidar.Get("model", &s.model, OneOf({"multibeam", "panoramic"}));
  lidar.Finish();
  r.Finish();
  return s;
}

// Expects a ConfigError whose message contains `key`.
void ExpectErrorNaming(const std::string& text, const std::string& key) {
  try {
    Load(text);
    FAIL() << "accepted: " << text;
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
  }
}

TEST(Config, ReadsValuesAndKeepsDefaults) {
  const Settings s = Load("lidar: {beams: 32}");
  EXPECT_EQ(s.beams, 32);
  EXPECT_EQ(s.max_range_m, 100);
  EXPECT_EQ(s.model, "multibeam");
}

TEST(Config, UnknownKeysAreNamed) {
  ExpectErrorNaming("lidar: {beams: 32, bemas: 3}", "lidar.bemas");
  ExpectErrorNaming("lidra: {}", "lidra");
}

TEST(Config, InvalidValuesNameTheKey) {
  ExpectErrorNaming("lidar: {max_range_m: -3}", "lidar.max_range_m");
  ExpectErrorNaming("lidar: {beams: 500}", "lidar.beams");
  ExpectErrorNaming("lidar: {beams: many}", "lidar.beams");
  ExpectErrorNaming("lidar: {model: solid_state}", "lidar.model");
  ExpectErrorNaming("lidar: {max_range_m: .nan}", "lidar.max_range_m");
}

// The message of a ConfigError that FailIfInvalid throws for `problem`, or "" when none.
std::string ValidationError(const std::string& problem, const std::map<std::string, std::string>& fields = {}) {
  ConfigReader root = ConfigReader::FromString("lidar: {beams: 500, max_range_m: 3}");
  ConfigReader lidar = root.Child("lidar");
  int beams = 0;
  double max_range_m = 0;
  lidar.Get("beams", &beams);
  lidar.Get("max_range_m", &max_range_m);
  try {
    lidar.FailIfInvalid(problem, fields);
    return "";
  } catch (const ConfigError& e) {
    return e.what();
  }
}

TEST(Config, ValidateMessagesNameTheKey) {
  EXPECT_EQ(ValidationError(""), "");
  EXPECT_EQ(ValidationError("beams: must be in [1, 128]"), "<string>: 'lidar.beams' must be in [1, 128]");
  EXPECT_EQ(ValidationError("max_range_m must be in [0, 1e5]"), "<string>: 'lidar.max_range_m' must be in [0, 1e5]");
  // A field that Validate() names otherwise.
  EXPECT_EQ(ValidationError("sensor.beams: must be in [1, 128]", {{"beams", "sensor.beams"}}),
            "<string>: 'lidar.beams' must be in [1, 128]");
  // Not about a key of the section (or only starting like one): the section is named.
  EXPECT_EQ(ValidationError("max_range_m_far: must be positive"),
            "<string>: 'lidar': max_range_m_far: must be positive");
  EXPECT_EQ(ValidationError("beams and rings must agree"), "<string>: 'lidar': beams and rings must agree");
}

TEST(Config, RequiredKeysAndSyntaxErrors) {
  ConfigReader r = ConfigReader::FromString("a: 1");
  int b = 0;
  try {
    r.Require("b", &b);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("'b' is required"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ConfigReader::FromString("a: [1, 2"), ConfigError);
  EXPECT_THROW(ConfigReader::FromFile("/nonexistent/config.yaml"), ConfigError);
}

}  // namespace
}  // namespace fusecal

#include "stages/formats/camera_file.hpp"

namespace fusecal {
namespace {

TEST(CameraFile, ParsesEveryModelAndRoundTrips) {
  const CameraParams p = ParseCameraYaml(
      "model: pinhole\nwidth: 1242\nheight: 375\nfx: 721.5\nfy: 721.5\ncx: 609.6\ncy: 172.9\n"
      "dist: [0.1, -0.2, 0, 0, 0.01]\n");
  EXPECT_EQ(p.width, 1242);
  EXPECT_EQ(p.dist[4], 0.01);
  const CameraParams back = ParseCameraYaml(CameraToYaml(p));
  EXPECT_EQ(back.fx, p.fx);
  EXPECT_EQ(back.dist, p.dist);
  EXPECT_EQ(ParseCameraYaml("model: equirectangular\nwidth: 2048\nheight: 1024\n").model, "equirectangular");
  const CameraParams fisheye = ParseCameraYaml(
      "model: equidistant\nwidth: 1024\nheight: 1024\nfx: 290\nfy: 291\ncx: 511.5\ncy: 510\n"
      "dist: [0.021, -0.0061, 0.0009, -0.0002]\n");
  EXPECT_EQ(fisheye.dist[3], -0.0002);
  EXPECT_EQ(ParseCameraYaml(CameraToYaml(fisheye)).dist, fisheye.dist);
  EXPECT_THROW(ParseCameraYaml("model: equidistant\nwidth: 10\nheight: 10\nfx: 1\nfy: 1\ncx: 1\ncy: 1\n"
                               "dist: [0, 0, 0, 0, 0]\n"),
               ConfigError);  // a fisheye has four coefficients
}

TEST(CameraFile, ErrorsNameTheKey) {
  for (const auto& [text, key] : std::vector<std::pair<std::string, std::string>>{
           {"model: fisheye\nwidth: 10\nheight: 10\n", "model"},
           {"model: equirectangular\nwidth: -10\nheight: 10\n", "width"},
           {"model: equirectangular\nwidth: 10\nheight: 10\nfov: 3\n", "fov"},
           {"model: pinhole\nwidth: 10\nheight: 10\nfx: 1\nfy: 1\ncx: 1\n", "cy"},
           {"model: pinhole\nwidth: 10\nheight: 10\nfx: 1\nfy: 1\ncx: 1\ncy: 1\ndist: [1]\n", "dist"}}) {
    try {
      ParseCameraYaml(text);
      ADD_FAILURE() << "accepted: " << text;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("'" + key), std::string::npos) << e.what();
    }
  }
}

// Expects LoadStrictYaml to fail with a message containing `what`.
void ExpectYamlError(const std::string& text, const std::string& what) {
  try {
    LoadStrictYaml(text, "f.yaml");
    ADD_FAILURE() << "accepted: " << text;
  } catch (const YamlError& e) {
    EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
  }
}

TEST(StrictYaml, EmptyEntriesInAFlowCollectionAreErrorsWithTheLine) {
  EXPECT_THROW(LoadStrictYaml("a: 1\nb: [1,,2]\n", "f.yaml"), YamlError);
  try {
    LoadStrictYaml("a: 1\nb: {c: [,1]}\n", "f.yaml");
    FAIL() << "an empty flow entry was accepted";
  } catch (const YamlError& e) {
    EXPECT_NE(std::string(e.what()).find("f.yaml:2: an empty entry in a flow collection"), std::string::npos)
        << e.what();
  }
  // Not empty entries: a trailing comma, commas in quotes, in comments and in block scalars.
  EXPECT_EQ(LoadStrictYaml("b: [1, 2, ]\n", "f.yaml")["b"].size(), 2u);
  EXPECT_EQ(LoadStrictYaml("b: \"x,,y\"  # p,,q\nc: [\"1,,\", '2,,']\n", "f.yaml")["c"].size(), 2u);
  EXPECT_EQ(LoadStrictYaml("note: a,,b\n", "f.yaml")["note"].as<std::string>(), "a,,b");
  // Thousands of them nested made yaml-cpp take minutes (fuzzing); refused at once.
  std::string nested = "[1";
  for (int i = 0; i < 40; ++i) nested += std::string(40, ',') + "{: [";
  const auto start = std::chrono::steady_clock::now();
  EXPECT_THROW(LoadStrictYaml(nested, "f.yaml"), YamlError);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
}

// Aliases nested ten at a time: 511 bytes that expand to 10^9 nodes (a "billion laughs") kept the check
// walking for more than a minute before the limit (found when fuzzing slowed down); refused at once with
// the file and line. An anchor used a few times is fine.
TEST(StrictYaml, AliasesThatExpandBeyondTheBudgetAreRefusedAtOnce) {
  std::string bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int i = 1; i <= 8; ++i) {
    bomb += "a" + std::to_string(i) + ": &a" + std::to_string(i) + " [";
    for (int k = 0; k < 10; ++k) bomb += (k ? ", *a" : "*a") + std::to_string(i - 1);
    bomb += "]\n";
  }
  const auto start = std::chrono::steady_clock::now();
  ExpectYamlError(bomb, "aliases (*name) expand the document to more than");
  ExpectYamlError(bomb, "f.yaml:");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 1.0);
  const YAML::Node ok = LoadStrictYaml("base: &b {fx: 1, fy: 2}\nleft: *b\nright: *b\n", "f.yaml");
  EXPECT_EQ(ok["right"]["fy"].as<int>(), 2);
}

TEST(StrictYaml, AKeyGivenTwiceIsAnErrorWithBothLines) {
  ExpectYamlError("a: 1\nb: 2\na: 3\n", "f.yaml:3: duplicate key 'a' (first at line 1)");
  ExpectYamlError("s:\n  x: 1\n  y: 2\n  x: 1\n", "f.yaml:4: duplicate key 'x'");
  ExpectYamlError("list:\n  - {k: 1, k: 2}\n", "duplicate key 'k'");
  EXPECT_NO_THROW(LoadStrictYaml("a: {x: 1}\nb: {x: 2}\n", "f.yaml"));  // the same key in two maps
}

TEST(StrictYaml, AQuoteLeftOpenIsAnErrorWhereItOpens) {
  ExpectYamlError("a: 1\nb: \"open\nc: 3\n", "f.yaml:2: a quoted value opens here and is never closed");
  ExpectYamlError("a: 'open\n", "f.yaml:1:");
  // Escapes are not closing quotes; closed values spanning lines are fine.
  ExpectYamlError("a: \"x\\\"\n", "never closed");
  EXPECT_EQ(LoadStrictYaml("a: 'it''s'\nb: \"q\\\"q\"\nc: \"two\n  lines\"\n", "f.yaml")["a"].as<std::string>(),
            "it's");
}

TEST(StrictYaml, SyntaxErrorsAndDirectoriesNameTheFileAndLine) {
  ExpectYamlError("a: [1, 2\nb: 1\n", "f.yaml:");
  try {
    LoadStrictYamlFile(::testing::TempDir());
    ADD_FAILURE() << "a directory was read as YAML";
  } catch (const YamlError& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  EXPECT_THROW(ConfigReader::FromString("a: 1\na: 2\n"), ConfigError);
}

TEST(BusUrl, EveryOptionOfEverySchemeIsCheckedByOneParser) {
  const ParsedBusUrl dds = ParseBusUrl("dds://?domain=7&shm=1&depth=16");
  EXPECT_EQ(dds.scheme, "dds");
  EXPECT_EQ(dds.Get("domain", 0), 7);
  EXPECT_EQ(dds.Get("bulk_depth", 8), 8);
  EXPECT_EQ(ParseBusUrl("udpm://239.255.76.67:7667?ttl=1").Get("ttl", 0), 1);
  EXPECT_NO_THROW(ParseBusUrl("file:///tmp/x.lcmlog?speed=2"));  // LCM's own options
  auto expect_refused = [](const std::string& url, const std::string& what) {
    try {
      ParseBusUrl(url);
      ADD_FAILURE() << "accepted: " << url;
    } catch (const BusError& e) {
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  expect_refused("iox://?max=banana", "max=banana is not an integer in [1024,");
  expect_refused("iox://?max=1e9", "max=1e9");
  expect_refused("dds://?depth=257", "depth=257");
  expect_refused("dds://?domian=1", "unknown parameter 'domian' (dds:// takes domain=");
  expect_refused("memq://?ttl=0", "memq:// takes none");
  expect_refused("udpm://239.255.76.67:7667?reliable=1", "use dds://");
  expect_refused("udpm://239.255.76.67", "GROUP:PORT");
  expect_refused("iox://somewhere", "takes no address");
  expect_refused("zmq://x", "unknown transport 'zmq'");
  expect_refused("239.255.76.67:7667", "has no scheme");
}

}  // namespace
}  // namespace fusecal
