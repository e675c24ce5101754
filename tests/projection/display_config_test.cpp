// display.json (FORMATS.md §4) and blend map files (§3): round trips and clear errors.
#include "facet/projection_io/display_config.hpp"

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <nlohmann/json.hpp>
#include <string>

#include "facet/projection/errors.hpp"
#include "facet/projection_io/blend_file.hpp"
#include "support/files.hpp"

namespace fs = std::filesystem;
namespace pio = facet::projection_io;
using nlohmann::json;

namespace {

json sample_document() {
  std::ifstream stream(fs::path(FACET_SOURCE_DIR) /
                       "configs/displays/sample_two_projectors.display.json");
  return json::parse(stream);
}

// The field an InputError names, or "" when none is thrown.
std::string failing_field(const json& document, const fs::path& folder = ".",
                          bool check_files = false) {
  try {
    pio::parse_display_config(document.dump(), "display.json", folder, check_files);
  } catch (const facet::InputError& e) {
    EXPECT_EQ(e.source(), "display.json");
    return e.field();
  }
  return "";
}

}  // namespace

TEST(DisplayConfig, SampleFileValidatesAndRoundTrips) {
  const pio::DisplayConfig config =
      pio::parse_display_config(sample_document().dump(), "sample", ".", false);
  ASSERT_EQ(config.projectors.size(), 2u);
  EXPECT_EQ(config.projectors[0].output.kind, pio::DisplayOutput::Kind::monitor);
  EXPECT_EQ(config.projectors[0].output.monitor, "DP-1");
  EXPECT_EQ(config.projectors[1].output.window, glm::ivec4(1024, 0, 1024, 768));
  EXPECT_FALSE(config.projectors[1].gamma.has_value());  // the default: sRGB
  EXPECT_EQ(config.missing_monitor, pio::MissingMonitor::window);
  EXPECT_EQ(config.eye, glm::dvec3(0, 1.2, 0));

  const facet::test::TempFolder folder("facet-display-test");
  pio::write_display_config(config, folder.path() / "display.json");
  const pio::DisplayConfig again = pio::read_display_config(folder.path(), false);
  pio::DisplayConfig expected = config;
  expected.folder = folder.path();
  EXPECT_EQ(again, expected);
}

TEST(DisplayConfig, SchemaParsesAndRequiresWhatTheReaderRequires) {
  std::ifstream stream(fs::path(FACET_SOURCE_DIR) / "configs/display.schema.json");
  const json schema = json::parse(stream);
  EXPECT_EQ(schema["properties"]["format"]["const"], pio::kDisplayFormat);
  for (const std::string field : {"format", "name", "eye", "projectors"}) {
    json document = sample_document();
    document.erase(field);
    EXPECT_EQ(failing_field(document), field);
    EXPECT_NE(std::find(schema["required"].begin(), schema["required"].end(), field),
              schema["required"].end());
  }
  for (const std::string field : {"name", "size", "warp", "output"}) {
    json document = sample_document();
    document["projectors"][1].erase(field);
    EXPECT_EQ(failing_field(document), "projectors[1]." + field);
    const json& required = schema["$defs"]["projector"]["required"];
    EXPECT_NE(std::find(required.begin(), required.end(), field), required.end());
  }
}

TEST(DisplayConfig, BadFieldsNameFileFieldAndExpectation) {
  auto with = [](const std::string& pointer, const json& value) {
    json document = sample_document();
    document[json::json_pointer(pointer)] = value;
    return document;
  };
  EXPECT_EQ(failing_field(with("/format", "facet-display/2")), "format");
  EXPECT_EQ(failing_field(with("/eye", json::array({0, "up", 0}))), "eye[1]");
  // Finite but no venue's: positions and radii beyond 1,000 km.
  EXPECT_EQ(failing_field(with("/eye", json::array({1e308, 1e308, 1e308}))), "eye");
  EXPECT_EQ(failing_field(with("/eye", json::array({0, 0, -1.5e6}))), "eye");
  EXPECT_EQ(failing_field(with("/eye", json::array({0, 0, -9e5}))), "");
  EXPECT_EQ(failing_field(with("/screen/radius", 1e300)), "screen.radius");
  EXPECT_EQ(failing_field(with("/projectors/0/size", json::array({1024}))), "projectors[0].size");
  EXPECT_EQ(failing_field(with("/projectors/0/size", json::array({1024, 0}))),
            "projectors[0].size");
  EXPECT_EQ(failing_field(with("/projectors/0/gamma", -1)), "projectors[0].gamma");
  EXPECT_EQ(failing_field(with("/projectors/0/warp", 3)), "projectors[0].warp");
  EXPECT_EQ(failing_field(with("/projectors/0/warp", "/abs/p0.warp.exr")), "projectors[0].warp");
  EXPECT_EQ(failing_field(with("/projectors/1/name", "p0")), "projectors[1].name");
  EXPECT_EQ(failing_field(with("/projectors/1/output", json{{"window", {0, 0, 0, 10}}})),
            "projectors[1].output.window");
  EXPECT_EQ(failing_field(with("/projectors/1/output", json{{"screen", "HDMI-1"}})),
            "projectors[1].output");
  EXPECT_EQ(failing_field(with("/missing_monitor", "ignore")), "missing_monitor");
  EXPECT_EQ(failing_field(with("/render/tolerance_px", 0)), "render.tolerance_px");
  EXPECT_EQ(failing_field(with("/render/method", "Facets!")), "render.method");
  EXPECT_EQ(failing_field(with("/screen/type", "torus")), "screen.type");
  // Unknown fields are refused; "x-" keys are free for notes.
  EXPECT_EQ(failing_field(with("/comment", "hello")), "comment");
  EXPECT_EQ(failing_field(with("/x-comment", "hello")), "");

  // NaN cannot be written in JSON, but a value built in code can hold it.
  pio::DisplayConfig config = pio::parse_display_config(sample_document().dump(), "s", ".", false);
  config.eye.y = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(pio::validate_display_config(config, "s", false), facet::InputError);
  const facet::test::TempFolder folder("facet-display-test");
  EXPECT_THROW(pio::write_display_config(config, folder.path() / "display.json"),
               facet::InputError);
  EXPECT_TRUE(fs::is_empty(folder.path()));
}

namespace {

// The message an InputError carries, or "" when none is thrown.
std::string failure(const json& document) {
  try {
    pio::parse_display_config(document.dump(), "site/display.json", ".", false);
  } catch (const facet::InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(DisplayConfig, MisspelledKeysAreRefusedWithTheNearestName) {
  json document = sample_document();
  document["projectors"][0]["blnd"] = document["projectors"][0]["blend"];
  document["projectors"][0].erase("blend");
  EXPECT_EQ(failure(document),
            "site/display.json: field 'projectors[0].blnd': unknown field 'blnd'; did you mean "
            "'blend'? (keys starting with \"x-\" are free for notes)");

  // Nested objects name the key by its path; swapped letters count as one edit.
  document = sample_document();
  document["projectors"][0]["output"]["positon"] = {0, 0};
  EXPECT_EQ(failing_field(document), "projectors[0].output.positon");
  EXPECT_NE(failure(document).find("did you mean 'position'"), std::string::npos);
  document = sample_document();
  document["render"]["tolerance"] = 0.5;
  EXPECT_NE(failure(document).find("did you mean 'tolerance_px'"), std::string::npos);
  document = sample_document();
  document["scren"] = document["screen"];
  document.erase("screen");
  EXPECT_NE(failure(document).find("field 'scren': unknown field 'scren'; did you mean 'screen'"),
            std::string::npos);
  // A window output has no fallback size: only the monitor form does.
  document = sample_document();
  document["projectors"][1]["output"]["size"] = {10, 10};
  EXPECT_EQ(failing_field(document), "projectors[1].output.size");

  // Nothing close: no guess, the known keys instead.
  document = sample_document();
  document["projectors"][1]["comment"] = "left of the door";
  const std::string far = failure(document);
  EXPECT_EQ(far.find("did you mean"), std::string::npos) << far;
  EXPECT_NE(far.find("known here: black, blend, gamma, name, output, size, warp"),
            std::string::npos)
      << far;

  // "x-" keys anywhere are users' notes.
  document = sample_document();
  document["x-site"] = "planetarium";
  document["projectors"][0]["x-serial"] = 1234;
  document["projectors"][0]["output"]["x-cable"] = "HDMI 3";
  document["render"]["x-why"] = "tuned for the 2026 show";
  document["screen"]["x-measured"] = json::object({{"by", "laser"}});
  EXPECT_EQ(failure(document), "");
}

TEST(DisplayConfig, TypeErrorsSayWhatWasExpectedAndWhatCame) {
  json document = sample_document();
  document["projectors"][0]["blend"] = 3;
  EXPECT_EQ(failure(document),
            "site/display.json: field 'projectors[0].blend': expected a string, got 3");
  document = sample_document();
  document["eye"] = "middle";
  EXPECT_EQ(failure(document),
            "site/display.json: field 'eye': expected a list of 3 numbers, got \"middle\"");
}

TEST(DisplayConfig, SchemaRefusesUnknownKeysButAllowsNotes) {
  std::ifstream stream(fs::path(FACET_SOURCE_DIR) / "configs/display.schema.json");
  const json schema = json::parse(stream);
  const json* objects[] = {&schema, &schema["properties"]["render"], &schema["$defs"]["projector"]};
  for (const json* object : objects) {
    EXPECT_EQ((*object)["additionalProperties"], false);
    EXPECT_EQ((*object)["patternProperties"]["^x-"], true);
  }
  for (const char* one_of : {"screen", "output"}) {
    for (const json& branch : schema["$defs"][one_of]["oneOf"]) {
      EXPECT_EQ(branch["additionalProperties"], false) << one_of;
      EXPECT_EQ(branch["patternProperties"]["^x-"], true) << one_of;
    }
  }
  // The keys the schema defines for a projector are exactly those the reader knows (listed, in
  // order, when a key is far from all of them; nlohmann keeps object keys sorted).
  std::string keys;
  for (const auto& [key, value] : schema["$defs"]["projector"]["properties"].items()) {
    keys += (keys.empty() ? "" : ", ") + key;
  }
  json document = sample_document();
  document["projectors"][1]["comment"] = "left of the door";
  EXPECT_NE(failure(document).find("known here: " + keys + ";"), std::string::npos)
      << failure(document);
}

TEST(DisplayConfig, ShippedDisplaysLoad) {
  int loaded = 0;
  for (const auto& entry :
       fs::directory_iterator(fs::path(FACET_SOURCE_DIR) / "configs/displays")) {
    if (!fs::is_regular_file(entry.path() / "display.json")) continue;
    SCOPED_TRACE(entry.path().string());
    EXPECT_NO_THROW(pio::read_display_config(entry.path()));
    ++loaded;
  }
  EXPECT_GE(loaded, 6);
}

TEST(DisplayConfig, MissingFilesAreNamed) {
  const facet::test::TempFolder folder("facet-display-test");
  for (const char* name : {"p0.warp.exr", "p0.blend.exr", "p1.warp.exr", "p1.blend.exr"}) {
    std::ofstream(folder.path() / name) << "x";
  }
  // p1.black.exr is missing.
  EXPECT_EQ(failing_field(sample_document(), folder.path(), true), "projectors[1].black");
  std::ofstream(folder.path() / "p1.black.exr") << "x";
  EXPECT_EQ(failing_field(sample_document(), folder.path(), true), "");
  fs::remove(folder.path() / "p0.warp.exr");
  EXPECT_EQ(failing_field(sample_document(), folder.path(), true), "projectors[0].warp");
}

namespace {

// The sample display (projectors p0 and p1) with a two-node cluster section.
json cluster_document() {
  json document = sample_document();
  document["cluster"] = {
      {"nodes",
       {{{"name", "left"},
         {"address", "tcp://10.0.0.1:7000"},
         {"projectors", {"p0"}},
         {"critical", true}},
        {{"name", "right"}, {"address", "ipc:///tmp/right"}, {"projectors", {"p1"}}}}},
      {"master", "left"},
      {"deadline_ms", 40}};
  return document;
}

}  // namespace

TEST(DisplayCluster, ReadsValidatesAndRoundTrips) {
  const pio::DisplayConfig config =
      pio::parse_display_config(cluster_document().dump(), "sample", ".", false);
  ASSERT_TRUE(config.cluster.has_value());
  const pio::DisplayCluster& cluster = *config.cluster;
  ASSERT_EQ(cluster.nodes.size(), 2u);
  EXPECT_EQ(cluster.master, "left");
  EXPECT_EQ(cluster.deadline_ms, 40.0);
  EXPECT_TRUE(cluster.nodes[0].critical);
  EXPECT_FALSE(cluster.nodes[1].critical);  // the default
  EXPECT_EQ(cluster.nodes[1].projectors, std::vector<std::string>{"p1"});
  EXPECT_EQ(pio::cluster_barrier_address("tcp://10.0.0.1:7000"), "tcp://10.0.0.1:7001");
  EXPECT_EQ(pio::cluster_barrier_address("ipc:///tmp/right"), "ipc:///tmp/right.barrier");

  const facet::test::TempFolder folder("facet-display-test");
  pio::write_display_config(config, folder.path() / "display.json");
  pio::DisplayConfig expected = config;
  expected.folder = folder.path();
  EXPECT_EQ(pio::read_display_config(folder.path(), false), expected);
  // Without a deadline, none is written and the reader leaves it to the default.
  expected.cluster->deadline_ms.reset();
  pio::write_display_config(expected, folder.path() / "display.json");
  EXPECT_EQ(pio::read_display_config(folder.path(), false), expected);
}

TEST(DisplayCluster, BadSectionsSayWhatIsWrong) {
  auto with = [](const std::string& pointer, const json& value) {
    json document = cluster_document();
    document[json::json_pointer(pointer)] = value;
    return document;
  };
  auto message = [](const json& document) {
    const std::string text = failure(document);
    return text.empty() ? std::string("no error") : text;
  };
  // An unknown projector, with the nearest name.
  std::string text = message(with("/cluster/nodes/1/projectors/0", "p2"));
  EXPECT_NE(text.find("field 'cluster.nodes[1].projectors[0]'"), std::string::npos) << text;
  EXPECT_NE(text.find("there is no 'p2'"), std::string::npos) << text;
  // A projector on two nodes, and one on none.
  text = message(with("/cluster/nodes/1/projectors", {"p1", "p0"}));
  EXPECT_NE(text.find("'p0' is also on node 'left'"), std::string::npos) << text;
  text = message(with("/cluster/nodes/1/projectors", json::array()));
  EXPECT_NE(text.find("cluster.nodes[1].projectors"), std::string::npos) << text;
  json document = cluster_document();
  document["cluster"]["nodes"].erase(1);
  text = message(document);
  EXPECT_NE(text.find("'p1' is on none"), std::string::npos) << text;
  // The master: missing, unknown (with the nearest name).
  document = cluster_document();
  document["cluster"].erase("master");
  EXPECT_EQ(failing_field(document), "cluster.master");
  text = message(with("/cluster/master", "lft"));
  EXPECT_NE(text.find("no node 'lft'; did you mean 'left'?"), std::string::npos) << text;
  // Node names and addresses.
  text = message(with("/cluster/nodes/1/name", "left"));
  EXPECT_NE(text.find("'left' repeats"), std::string::npos) << text;
  for (const char* address :
       {"10.0.0.1:7000", "tcp://10.0.0.1", "tcp://10.0.0.1:0", "tcp://10.0.0.1:65535",
        "tcp://host:70x", "udp://h:1", "ipc://", "tcp://bad host:7000"}) {
    text = message(with("/cluster/nodes/1/address", address));
    EXPECT_NE(text.find("field 'cluster.nodes[1].address': expected tcp://HOST:PORT"),
              std::string::npos)
        << address << ": " << text;
  }
  // The barrier listens on the next port: 7001 belongs to the first node already.
  text = message(with("/cluster/nodes/1/address", "tcp://10.0.0.1:7001"));
  EXPECT_NE(text.find("tcp://10.0.0.1:7001 is another node's"), std::string::npos) << text;
  EXPECT_EQ(failing_field(with("/cluster/nodes/1/address", "tcp://10.0.0.2:7001")), "");
  EXPECT_EQ(failing_field(with("/cluster/deadline_ms", 0)), "cluster.deadline_ms");
  EXPECT_EQ(failing_field(with("/cluster/deadline_ms", 1e9)), "cluster.deadline_ms");
  EXPECT_EQ(failing_field(with("/cluster/nodes/0/critical", "yes")), "cluster.nodes[0].critical");
  EXPECT_EQ(failing_field(with("/cluster/nodes", json::array())), "cluster.nodes");
  // Misspelled keys, as everywhere in display.json.
  document = cluster_document();
  document["cluster"]["nodes"][0]["adress"] = "tcp://h:1";
  text = message(document);
  EXPECT_NE(text.find("did you mean 'address'?"), std::string::npos) << text;
  document = cluster_document();
  document["cluster"]["dedline_ms"] = 10;
  text = message(document);
  EXPECT_NE(text.find("did you mean 'deadline_ms'?"), std::string::npos) << text;
}

TEST(DisplayCluster, SchemaKnowsTheKeysTheReaderKnows) {
  std::ifstream stream(fs::path(FACET_SOURCE_DIR) / "configs/display.schema.json");
  const json schema = json::parse(stream);
  ASSERT_TRUE(schema["properties"].contains("cluster"));
  for (const char* def : {"cluster", "cluster_node"}) {
    const json& object = schema["$defs"][def];
    EXPECT_EQ(object["additionalProperties"], false) << def;
    EXPECT_EQ(object["patternProperties"]["^x-"], true) << def;
  }
  std::string keys;
  for (const auto& [key, value] : schema["$defs"]["cluster_node"]["properties"].items())
    keys += (keys.empty() ? "" : ", ") + key;
  json document = cluster_document();
  document["cluster"]["nodes"][0]["comment"] = "rack 2";
  EXPECT_NE(failure(document).find("known here: " + keys + ";"), std::string::npos)
      << failure(document);
}

TEST(BlendFile, RoundTripsAndSamples) {
  const facet::test::TempFolder folder("facet-display-test");
  pio::BlendMap map = pio::BlendMap::constant({5, 3}, 0.0f);
  for (int y = 0; y < 3; ++y) {
    for (int x = 0; x < 5; ++x) map.at(x, y) = float(x) / 4.0f;
  }
  const std::string path = (folder.path() / "p.blend.exr").string();
  pio::write_blend_map(path, map);
  const pio::BlendMap again = pio::read_blend_map(path, glm::ivec2(5, 3));
  EXPECT_EQ(again.values, map.values);
  EXPECT_EQ(again.channels, 1);
  // Bilinear between pixel centres (x + 0.5).
  EXPECT_NEAR(again.sample({1.0, 1.5}), 0.125, 1e-7);
  EXPECT_THROW(pio::read_blend_map(path, glm::ivec2(6, 3)), facet::InputError);
}

TEST(BlendFile, BadMapsAreRejectedAndNothingIsWritten) {
  const facet::test::TempFolder folder("facet-display-test");
  pio::BlendMap map = pio::BlendMap::constant({4, 4}, 0.5f);
  map.at(2, 1) = 1.5f;
  try {
    pio::write_blend_map((folder.path() / "bad.blend.exr").string(), map);
    FAIL() << "no error";
  } catch (const facet::InputError& e) {
    EXPECT_EQ(e.field(), "pixel (2, 1)");
  }
  map.at(2, 1) = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(pio::write_blend_map((folder.path() / "bad.blend.exr").string(), map),
               facet::InputError);
  EXPECT_TRUE(fs::is_empty(folder.path()));

  // An EXR without the facet:blend attribute.
  const std::string plain = (folder.path() / "plain.exr").string();
  {
    auto output = OIIO::ImageOutput::create("openexr");
    OIIO::ImageSpec spec(2, 2, 1, OIIO::TypeDesc::FLOAT);
    spec.channelnames = {"Y"};
    ASSERT_TRUE(output->open(plain, spec));
    const float pixels[4] = {0, 0, 0, 0};
    ASSERT_TRUE(output->write_image(OIIO::TypeDesc::FLOAT, pixels));
    output->close();
  }
  try {
    pio::read_blend_map(plain);
    FAIL() << "no error";
  } catch (const facet::InputError& e) {
    EXPECT_EQ(e.field(), "facet:blend");
    EXPECT_EQ(e.source(), plain);
  }
  EXPECT_THROW(pio::read_blend_map((folder.path() / "missing.blend.exr").string()),
               facet::InputError);
}
