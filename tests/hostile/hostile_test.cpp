// Hostile-input suite (issue 19): bad variants of every input kind facet reads, each run through
// the CLI in its own scratch folder under a 2 GiB address-space limit and a wall-clock limit.
// Every variant must end with exit status 2 (a user mistake, not an internal error, a crash or a
// hang), a message on stderr naming the input or the field, and no output left behind: neither
// the output path nor a hidden temporary (.NAME.tmp*) in the scratch folder.
//
// The variants are derived from real valid files (configs/, the shared data in
// ../shared/data, and small files written here): truncations, flipped magic bytes, wrong JSON
// types, NaN/Inf/huge/negative numbers, huge sizes and counts, empty files, directories, FIFOs
// and /dev/null where a file is expected, invalid UTF-8, deep nesting, zip-slip paths, XML entity
// bombs, glTF accessors past their buffers, buffer URIs leaving the folder and node cycles.
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/sysmacros.h>
#include <sys/time.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#include <zip.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iostream>
#include <iterator>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/videoio.hpp>
#include <set>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "../../tools/cli/command.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

const fs::path kSource = FACET_SOURCE_DIR;
const fs::path kShared = FACET_SHARED_DATA_DIR;
constexpr rlim_t kAddressSpaceLimit = rlim_t{2} << 30;  // 2 GiB
constexpr long kMaxResidentKiB = 2L << 20;              // 2 GiB in KiB (ru_maxrss)
constexpr auto kWallLimit = std::chrono::seconds(20);

std::string slurp(const fs::path& path) {
  std::ifstream stream(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(stream), std::istreambuf_iterator<char>()};
}

void spit(const fs::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// One hostile variant: `make` writes the inputs into the scratch folder; `args` are the CLI's
// arguments, where a leading '@' stands for the scratch folder; `output` is the path (relative to
// the scratch folder) the command would write; stderr must contain one of `mentions`.
struct Variant {
  std::string name;
  std::function<void(const fs::path&)> make;
  std::vector<std::string> args;
  std::string output;
  std::vector<std::string> mentions;
  // `make` writes with OpenImageIO, OpenEXR or OpenCV, whose pools of threads must not start in
  // this process (see run_cli): it runs in a forked child. Without, it runs here (one fork less).
  bool make_starts_threads = true;
};

// Variants that fail only under the suite's address-space limit (a size a machine with that much
// memory cannot hold): the sanitizer build runs without the limit, so it skips them.
std::set<std::string>& address_limited() {
  static std::set<std::string> names;
  return names;
}

// ---- Byte-level mutations of a valid file -------------------------------------------------------

std::string truncated(const std::string& bytes, std::size_t size) {
  return bytes.substr(0, std::min(size, bytes.size()));
}

std::string flipped(std::string bytes, std::size_t offset) {
  if (offset < bytes.size()) bytes[offset] = static_cast<char>(bytes[offset] ^ 0xff);
  return bytes;
}

// The byte-level variants of `base` written as `file`: empty, truncated at several offsets and
// with the first bytes (the magic or the first token) flipped.
void add_byte_variants(std::vector<Variant>& out, const std::string& prefix,
                       const std::function<std::string()>& base, const std::string& file,
                       const std::function<void(const fs::path&)>& context,
                       const std::vector<std::string>& args, const std::string& output,
                       const std::vector<double>& fractions = {0.001, 0.1, 0.5, 0.9, 0.999},
                       bool flip = true) {
  auto add = [&](const std::string& what, std::function<std::string(const std::string&)> mutate) {
    out.push_back({prefix + "_" + what,
                   [=](const fs::path& dir) {
                     if (context) context(dir);
                     spit(dir / file, mutate(base()));
                   },
                   args,
                   output,
                   {fs::path(file).filename().string()}});
  };
  add("empty", [](const std::string&) { return std::string(); });
  for (const double f : fractions) {
    add("truncated_" + std::to_string(static_cast<int>(f * 1000)) + "permille",
        [f](const std::string& b) {
          return truncated(b, std::max<std::size_t>(
                                  1, static_cast<std::size_t>(static_cast<double>(b.size()) * f)));
        });
  }
  if (flip) {
    add("magic_flipped", [](const std::string& b) { return flipped(flipped(b, 0), 1); });
  }
  add("binary_garbage", [](const std::string& b) {
    std::string g(std::min<std::size_t>(b.size(), 4096), '\0');
    for (std::size_t i = 0; i < g.size(); ++i) g[i] = static_cast<char>((i * 2654435761u) >> 13);
    return g;
  });
}

// Non-regular files where `file` is expected: a directory, a FIFO (opening it for reading would
// block forever), a symbolic link to /dev/zero (endless), a dangling link and a missing file.
void add_non_regular_variants(std::vector<Variant>& out, const std::string& prefix,
                              const std::string& file,
                              const std::function<void(const fs::path&)>& context,
                              const std::vector<std::string>& args, const std::string& output) {
  const std::string name = fs::path(file).filename().string();
  auto add = [&](const std::string& what, std::function<void(const fs::path&)> make) {
    out.push_back({prefix + "_" + what,
                   [=](const fs::path& dir) {
                     if (context) context(dir);
                     std::error_code ec;
                     fs::remove(dir / file, ec);
                     make(dir / file);
                   },
                   args,
                   output,
                   {name}});
  };
  add("directory", [](const fs::path& p) { fs::create_directories(p); });
  add("fifo", [](const fs::path& p) { ::mkfifo(p.c_str(), 0644); });
  add("link_to_dev_zero", [](const fs::path& p) { fs::create_symlink("/dev/zero", p); });
  add("dangling_link", [](const fs::path& p) { fs::create_symlink(p.string() + ".gone", p); });
  add("missing", [](const fs::path&) {});
}

// ---- JSON mutations -----------------------------------------------------------------------------

// `base` with the value at `pointer` replaced by `raw` JSON text (which may be invalid JSON, such
// as NaN, or hold invalid UTF-8); an empty `raw` removes the member.
std::string json_with(const json& base, const std::string& pointer, const std::string& raw) {
  json copy = base;
  const json::json_pointer ptr(pointer);
  if (raw.empty()) {
    copy[ptr.parent_pointer()].erase(ptr.back());
    return copy.dump(1);
  }
  copy[ptr] = "@@HOSTILE@@";
  std::string text = copy.dump(1);
  const std::string marker = "\"@@HOSTILE@@\"";
  text.replace(text.find(marker), marker.size(), raw);
  return text;
}

struct FieldMutation {
  std::string what;     // names the variant
  std::string pointer;  // JSON pointer of the field
  std::string raw;      // its new raw JSON text ("" removes it)
  std::string mention;  // a word stderr must hold besides the file name
};

std::string sanitize(std::string name) {
  for (char& c : name) {
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  }
  return name;
}

void add_json_variants(std::vector<Variant>& out, const std::string& prefix,
                       const std::function<json()>& base, const std::string& file,
                       const std::function<void(const fs::path&)>& context,
                       const std::vector<FieldMutation>& mutations,
                       const std::vector<std::string>& args, const std::string& output) {
  const std::string name = fs::path(file).filename().string();
  for (const FieldMutation& m : mutations) {
    out.push_back({prefix + "_" + sanitize(m.what),
                   [=](const fs::path& dir) {
                     if (context) context(dir);
                     spit(dir / file, json_with(base(), m.pointer, m.raw));
                   },
                   args,
                   output,
                   {name, m.mention}});
  }
  // Whole-document variants.
  auto add_text = [&](const std::string& what, std::function<std::string()> text) {
    out.push_back({prefix + "_" + what,
                   [=](const fs::path& dir) {
                     if (context) context(dir);
                     spit(dir / file, text());
                   },
                   args,
                   output,
                   {name}});
  };
  add_text("deeply_nested", [] { return std::string(100000, '[') + std::string(100000, ']'); });
  add_text("top_level_array", [] { return std::string("[1, 2, 3]"); });
  add_text("top_level_string", [] { return std::string("\"facet\""); });
  add_text("null", [] { return std::string("null"); });
  add_text("invalid_utf8_key", [base] {
    std::string text = base().dump(1);
    return text.insert(text.find('{') + 1, "\"\xff\xfe\xc0\x80\": 1,");
  });
  add_text("trailing_garbage", [base] { return base().dump(1) + "\n}{"; });
}

// ---- EXR writing (OpenImageIO) ------------------------------------------------------------------

struct Exr {
  int width = 0, height = 0;
  std::vector<std::string> channels;
  std::vector<float> pixels;
  std::vector<std::pair<std::string, std::string>> attributes;
};

Exr read_exr(const fs::path& path) {
  Exr exr;
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) return exr;
  const OIIO::ImageSpec& spec = in->spec();
  exr.width = spec.width;
  exr.height = spec.height;
  exr.channels = spec.channelnames;
  exr.pixels.resize(static_cast<std::size_t>(spec.width) * spec.height * spec.nchannels);
  in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::FLOAT, exr.pixels.data());
  for (const auto& attribute : spec.extra_attribs) {
    if (attribute.name().string().starts_with("facet:")) {
      exr.attributes.emplace_back(attribute.name().string(), attribute.get_string());
    }
  }
  return exr;
}

void write_exr(const fs::path& path, const Exr& exr) {
  OIIO::ImageSpec spec(exr.width, exr.height, static_cast<int>(exr.channels.size()),
                       OIIO::TypeDesc::FLOAT);
  spec.channelnames = exr.channels;
  for (const auto& [key, value] : exr.attributes) spec.attribute(key, value);
  auto out = OIIO::ImageOutput::create(path.string());
  if (!out || !out->open(path.string(), spec)) return;
  out->write_image(OIIO::TypeDesc::FLOAT, exr.pixels.data());
  out->close();
}

// The EXR's bytes with its dataWindow (box2i) made `width` × `height` pixels: the header then
// promises far more pixels than the file holds.
std::string exr_with_data_window(std::string bytes, std::int32_t x_max, std::int32_t y_max) {
  const std::string key = std::string("dataWindow\0box2i\0", 17);
  const std::size_t at = bytes.find(key);
  if (at == std::string::npos) return bytes;
  const std::size_t box = at + key.size() + 4;  // after the attribute size
  std::memcpy(&bytes[box + 8], &x_max, 4);
  std::memcpy(&bytes[box + 12], &y_max, 4);
  return bytes;
}

// ---- zip writing (libzip) -----------------------------------------------------------------------

using Entries = std::vector<std::pair<std::string, std::string>>;

Entries read_zip(const fs::path& path) {
  Entries entries;
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_RDONLY, &error);
  if (!archive) return entries;
  const zip_int64_t count = zip_get_num_entries(archive, 0);
  for (zip_int64_t i = 0; i < count; ++i) {
    zip_stat_t stat;
    zip_stat_index(archive, static_cast<zip_uint64_t>(i), 0, &stat);
    std::string data(stat.size, '\0');
    zip_file_t* file = zip_fopen_index(archive, static_cast<zip_uint64_t>(i), 0);
    if (file) {
      zip_fread(file, data.data(), stat.size);
      zip_fclose(file);
    }
    entries.emplace_back(stat.name, std::move(data));
  }
  zip_close(archive);
  return entries;
}

// Adds an entry holding `data`. zip_source_buffer keeps a pointer: the bytes are copied into
// memory that lives until zip_close, which frees it (libzip frees no buffer of length 0, so an
// empty entry gets none).
void add_zip_entry(zip_t* archive, const std::string& name, const std::string& data,
                   zip_flags_t flags) {
  void* copy = nullptr;
  if (!data.empty()) {
    copy = std::malloc(data.size());
    std::memcpy(copy, data.data(), data.size());
  }
  zip_source_t* source = zip_source_buffer(archive, copy, data.size(), copy ? 1 : 0);
  if (zip_file_add(archive, name.c_str(), source, flags) < 0) zip_source_free(source);
}

void write_zip(const fs::path& path, const Entries& entries) {
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  if (!archive) return;
  for (const auto& [name, data] : entries)
    add_zip_entry(archive, name, data, ZIP_FL_ENC_RAW | ZIP_FL_OVERWRITE);
  zip_close(archive);
}

// A zip entry of `size` zero bytes, compressed (a zip bomb in miniature): written by streaming
// a callback source so the test never holds it in memory.
void write_zip_bomb(const fs::path& path, const Entries& entries, const std::string& name,
                    zip_uint64_t size) {
  int error = 0;
  zip_t* archive = zip_open(path.c_str(), ZIP_CREATE | ZIP_TRUNCATE, &error);
  if (!archive) return;
  for (const auto& [entry, data] : entries) add_zip_entry(archive, entry, data, ZIP_FL_OVERWRITE);
  struct Zeros {
    zip_uint64_t left;
  };
  auto* state = new Zeros{size};
  auto callback = [](void* user, void* data, zip_uint64_t length,
                     zip_source_cmd_t command) -> zip_int64_t {
    auto* zeros = static_cast<Zeros*>(user);
    switch (command) {
      case ZIP_SOURCE_OPEN:
      case ZIP_SOURCE_CLOSE:
        return 0;
      case ZIP_SOURCE_READ: {
        const zip_uint64_t n = std::min(length, zeros->left);
        std::memset(data, 0, n);
        zeros->left -= n;
        return static_cast<zip_int64_t>(n);
      }
      case ZIP_SOURCE_STAT: {
        auto* stat = static_cast<zip_stat_t*>(data);
        zip_stat_init(stat);
        return sizeof(zip_stat_t);
      }
      case ZIP_SOURCE_FREE:
        delete zeros;
        return 0;
      case ZIP_SOURCE_SUPPORTS:
        return zip_source_make_command_bitmap(ZIP_SOURCE_OPEN, ZIP_SOURCE_READ, ZIP_SOURCE_CLOSE,
                                              ZIP_SOURCE_STAT, ZIP_SOURCE_FREE, -1);
      default:
        return -1;
    }
  };
  zip_source_t* source = zip_source_function(archive, callback, state);
  zip_int64_t index = zip_file_add(archive, name.c_str(), source, ZIP_FL_OVERWRITE);
  zip_set_file_compression(archive, static_cast<zip_uint64_t>(index), ZIP_CM_DEFLATE, 1);
  zip_close(archive);
}

// ---- Helpers for folders of valid inputs --------------------------------------------------------

void link_all(const fs::path& from, const fs::path& to, const std::string& except) {
  fs::create_directories(to);
  for (const auto& entry : fs::directory_iterator(from)) {
    const std::string name = entry.path().filename().string();
    if (name == except) continue;
    fs::create_symlink(entry.path(), to / name);
  }
}

std::string replace_all(std::string text, const std::string& from, const std::string& to) {
  for (std::size_t at = text.find(from); at != std::string::npos;
       at = text.find(from, at + to.size())) {
    text.replace(at, from.size(), to);
  }
  return text;
}

std::string replace_first(std::string text, const std::string& from, const std::string& to) {
  const std::size_t at = text.find(from);
  if (at != std::string::npos) text.replace(at, from.size(), to);
  return text;
}

// An XML entity-expansion bomb ("billion laughs") in front of `root`.
std::string entity_bomb(const std::string& root) {
  std::string text = "<?xml version=\"1.0\"?>\n<!DOCTYPE lolz [\n <!ENTITY lol \"lol\">\n";
  for (int i = 1; i <= 9; ++i) {
    text += " <!ENTITY lol" + std::to_string(i) + " \"";
    for (int j = 0; j < 10; ++j)
      text += "&lol" + (i == 1 ? std::string() : std::to_string(i - 1)) + ";";
    text += "\">\n";
  }
  return text + "]>\n<" + root + ">&lol9;</" + root + ">\n";
}

std::string deep_xml(const std::string& root) {
  std::string text = "<?xml version=\"1.0\"?>\n<" + root + ">";
  for (int i = 0; i < 200000; ++i) text += "<a>";
  for (int i = 0; i < 200000; ++i) text += "</a>";
  return text + "</" + root + ">\n";
}

// ---- The variants of every input kind ----------------------------------------------------------

// display.json: configs/displays/cylinder3 with its warps and blends linked in.
json display_base() {
  return json::parse(slurp(kSource / "configs/displays/cylinder3/display.json"));
}

void display_context(const fs::path& dir) {
  link_all(kSource / "configs/displays/cylinder3", dir, "display.json");
}

void add_display_json(std::vector<Variant>& out) {
  const std::vector<std::string> args{"display", "@display.json", "--out", "@out"};
  add_byte_variants(
      out, "display_json", [] { return display_base().dump(1); }, "display.json", display_context,
      args, "out", {0.001, 0.3, 0.6, 0.999}, false);
  add_non_regular_variants(out, "display_json", "display.json", nullptr, args, "out");
  std::vector<FieldMutation> m = {
      {"format_number", "/format", "1", "format"},
      {"format_unknown", "/format", "\"facet-display/99\"", "format"},
      {"format_missing", "/format", "", "format"},
      {"projectors_object", "/projectors", "{}", "projectors"},
      {"projectors_empty", "/projectors", "[]", "projectors"},
      {"projector_null", "/projectors/0", "null", "projectors"},
      {"name_invalid_utf8", "/projectors/0/name", "\"p\xff\xfe\"", "name"},
      {"name_number", "/projectors/0/name", "7", "name"},
      {"name_path_escape", "/projectors/0/name", "\"../../escape\"", "name"},
      {"name_duplicate", "/projectors/1/name", "\"p0\"", "name"},
      {"size_string", "/projectors/0/size", "\"1024x512\"", "size"},
      {"size_short", "/projectors/0/size", "[1024]", "size"},
      {"size_negative", "/projectors/0/size", "[-1, 512]", "size"},
      {"size_zero", "/projectors/0/size", "[0, 0]", "size"},
      {"size_1e308", "/projectors/0/size", "[1e308, 512]", "size"},
      {"size_huge_int", "/projectors/0/size", "[4294967296000, 512]", "size"},
      {"size_fraction", "/projectors/0/size", "[1024.5, 512]", "size"},
      {"size_nan", "/projectors/0/size", "[NaN, 512]", "size"},
      {"window_negative_width", "/projectors/0/output/window", "[0, 0, -5, 512]", "window"},
      {"window_string", "/projectors/0/output/window", "\"left\"", "window"},
      {"warp_missing_file", "/projectors/0/warp", "\"nowhere.warp.exr\"", "nowhere"},
      {"warp_number", "/projectors/0/warp", "3", "warp"},
      {"warp_dev_null", "/projectors/0/warp", "\"/dev/null\"", "/dev/null"},
      {"warp_directory", "/projectors/0/warp", "\".\"", "warp"},
      {"warp_etc_passwd", "/projectors/0/warp", "\"../../../../../../etc/passwd\"", "passwd"},
      {"blend_missing_file", "/projectors/0/blend", "\"nowhere.blend.exr\"", "nowhere"},
      {"blend_array", "/projectors/0/blend", "[]", "blend"},
      {"gamma_bogus", "/projectors/0/gamma", "\"bogus\"", "gamma"},
      {"gamma_negative", "/projectors/0/gamma", "-2.2", "gamma"},
      {"radius_negative", "/screen/radius", "-1", "radius"},
      {"radius_zero", "/screen/radius", "0", "radius"},
      {"radius_inf", "/screen/radius", "1e999", "radius"},
      {"screen_type_bogus", "/screen/type", "\"banana\"", "type"},
      {"axis_zero", "/screen/axis", "[0, 0, 0]", "axis"},
      {"eye_string_element", "/eye", "[\"a\", 0, 0]", "eye"},
      {"eye_inf", "/eye", "[1e999, 0, 0]", "eye"},
      {"eye_far", "/eye", "[1e308, 1e308, 1e308]", "eye"},
      {"radius_far", "/screen/radius", "1e300", "radius"},
      {"tolerance_negative", "/render/tolerance_px", "-1", "tolerance"},
      {"tolerance_zero", "/render/tolerance_px", "0", "tolerance"},
      {"z_near_negative", "/render/z_near", "-0.05", "z_near"},
      {"missing_monitor_bogus", "/missing_monitor", "\"bogus\"", "missing_monitor"},
      {"unknown_key", "/surprise", "1", "surprise"},
  };
  add_json_variants(out, "display_json", display_base, "display.json", display_context, m, args,
                    "out");
  out.push_back({"display_json_run_method_bogus",
                 [](const fs::path& dir) {
                   display_context(dir);
                   spit(dir / "display.json",
                        json_with(display_base(), "/render/method", "\"bogus\""));
                 },
                 {"run", "@display.json", "--headless", "--frames", "1", "--out", "@out"},
                 "out",
                 {"display.json"}});
  // The same file through the commands that render it (GL, slower: a few of each).
  for (const FieldMutation& f : {m[4], m[12], m[20], m[29]}) {
    out.push_back({"display_json_run_" + sanitize(f.what),
                   [f](const fs::path& dir) {
                     display_context(dir);
                     spit(dir / "display.json", json_with(display_base(), f.pointer, f.raw));
                   },
                   {"run", "@display.json", "--headless", "--frames", "1", "--out", "@out"},
                   "out",
                   {"display.json", f.mention}});
    out.push_back({"display_json_render_" + sanitize(f.what),
                   [f](const fs::path& dir) {
                     display_context(dir);
                     spit(dir / "display.json", json_with(display_base(), f.pointer, f.raw));
                   },
                   {"render", "--display", "@display.json", "--out", "@out"},
                   "out",
                   {"display.json", f.mention}});
  }
}

// .warp.exr: configs/displays/dome180/dome180.warp.exr (2×2 nodes, facet:warp metadata).
void add_warp_exr(std::vector<Variant>& out) {
  const fs::path source = kSource / "configs/displays/dome180/dome180.warp.exr";
  const std::vector<std::string> lookup{"lookup", "--warp", "@x.warp.exr", "--out", "@out.exr"};
  add_byte_variants(
      out, "warp_exr", [source] { return slurp(source); }, "x.warp.exr", nullptr, lookup,
      "out.exr");
  add_non_regular_variants(out, "warp_exr", "x.warp.exr", nullptr, lookup, "out.exr");
  out.push_back({"warp_exr_data_window_huge",
                 [source](const fs::path& dir) {
                   spit(dir / "x.warp.exr", exr_with_data_window(slurp(source), 1 << 30, 1 << 30));
                 },
                 lookup,
                 "out.exr",
                 {"x.warp.exr"}});
  out.push_back({"warp_exr_data_window_inverted",
                 [source](const fs::path& dir) {
                   spit(dir / "x.warp.exr", exr_with_data_window(slurp(source), -5, -5));
                 },
                 lookup,
                 "out.exr",
                 {"x.warp.exr"}});
  out.push_back({"warp_exr_png_renamed",
                 [](const fs::path& dir) {
                   fs::copy_file(kShared / "warps/sgct-dome/sciss/channel1.png",
                                 dir / "x.warp.exr");
                 },
                 lookup,
                 "out.exr",
                 {"x.warp.exr"}});
  // Written with OpenImageIO: the metadata or the pixels made wrong.
  auto add_exr = [&](const std::string& what, std::function<void(Exr&)> mutate,
                     const std::string& mention) {
    out.push_back({"warp_exr_" + what,
                   [source, mutate](const fs::path& dir) {
                     Exr exr = read_exr(source);
                     mutate(exr);
                     write_exr(dir / "x.warp.exr", exr);
                   },
                   lookup,
                   "out.exr",
                   {"x.warp.exr", mention}});
  };
  auto with_meta = [](const std::string& pointer, const std::string& raw) {
    return [pointer, raw](Exr& exr) {
      for (auto& [key, value] : exr.attributes) {
        if (key == "facet:warp") value = json_with(json::parse(value), pointer, raw);
      }
    };
  };
  add_exr(
      "meta_missing", [](Exr& exr) { exr.attributes.clear(); }, "facet:warp");
  add_exr(
      "meta_not_json",
      [](Exr& exr) {
        exr.attributes = {{"facet:warp", "{"}};
      },
      "facet:warp");
  add_exr("meta_format_unknown", with_meta("/format", "\"facet-warp/9\""), "format");
  add_exr("meta_base_bogus", with_meta("/base", "\"bogus\""), "base");
  add_exr("meta_fov_negative", with_meta("/fov", "-1"), "fov");
  add_exr("meta_fov_zero", with_meta("/fov", "0"), "fov");
  add_exr("meta_fov_1e308", with_meta("/fov", "1e308"), "fov");
  add_exr("meta_fov_string", with_meta("/fov", "\"wide\""), "fov");
  add_exr("meta_output_size_negative", with_meta("/output_size", "[-1, 2048]"), "output_size");
  add_exr("meta_output_size_zero", with_meta("/output_size", "[0, 0]"), "output_size");
  add_exr("meta_output_size_huge", with_meta("/output_size", "[1000000, 1000000]"), "output_size");
  add_exr("meta_output_size_short", with_meta("/output_size", "[2048]"), "output_size");
  // Within the size limits, but the lookup's tables need about 4 GiB: refused up front.
  add_exr("meta_output_size_over_memory", with_meta("/output_size", "[8192, 8192]"), "output_size");
  address_limited().insert("warp_exr_meta_output_size_over_memory");
  add_exr("meta_rotation_zero", with_meta("/rotation", "[[0,0,0],[0,0,0],[0,0,0]]"), "rotation");
  add_exr("meta_rotation_shape", with_meta("/rotation", "[1, 2, 3]"), "rotation");
  add_exr("meta_invalid_utf8", with_meta("/base", "\"\xff\xfe\""), "base");
  add_exr(
      "pixel_nan", [](Exr& exr) { exr.pixels[0] = std::numeric_limits<float>::quiet_NaN(); },
      "x.warp.exr");
  add_exr(
      "pixel_inf", [](Exr& exr) { exr.pixels[1] = std::numeric_limits<float>::infinity(); },
      "x.warp.exr");
  add_exr(
      "two_channels",
      [](Exr& exr) {
        std::vector<float> rg;
        for (std::size_t i = 0; i < exr.pixels.size(); i += 3) {
          rg.push_back(exr.pixels[i]);
          rg.push_back(exr.pixels[i + 1]);
        }
        exr.pixels = rg;
        exr.channels = {"R", "G"};
      },
      "x.warp.exr");
  add_exr(
      "channels_renamed",
      [](Exr& exr) {
        exr.channels = {"X", "Y", "Z"};
      },
      "x.warp.exr");
  add_exr(
      "one_node",
      [](Exr& exr) {
        exr.width = exr.height = 1;
        exr.pixels.resize(3);
      },
      "x.warp.exr");
  // The same file through the other commands that read a warp.
  for (const std::string what : {"empty", "truncated_500permille", "fifo", "directory"}) {
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (out[i].name != "warp_exr_" + what) continue;
      Variant v = out[i];
      v.name = "warp_exr_display_" + what;
      v.args = {"display", "@x.warp.exr", "--out", "@out"};
      v.output = "out";
      out.push_back(v);
      v.name = "warp_exr_render_" + what;
      v.args = {"render", "--display", "@x.warp.exr", "--out", "@out"};
      out.push_back(v);
      break;
    }
  }
}

// Blend EXR: p0's blend of cylinder3 replaced (1024×512, one channel Y, facet:blend metadata).
void add_blend_exr(std::vector<Variant>& out) {
  const fs::path source = kSource / "configs/displays/cylinder3/p0.blend.exr";
  auto context = [](const fs::path& dir) {
    link_all(kSource / "configs/displays/cylinder3", dir, "p0.blend.exr");
  };
  const std::vector<std::string> args{"display", "@display.json", "--out", "@out"};
  add_byte_variants(out, "blend_exr", [source] { return slurp(source); }, "p0.blend.exr", context,
                    args, "out", {0.001, 0.01, 0.5, 0.99});
  add_non_regular_variants(out, "blend_exr", "p0.blend.exr", context, args, "out");
  auto add_exr = [&](const std::string& what, std::function<void(Exr&)> mutate) {
    out.push_back({"blend_exr_" + what,
                   [source, mutate, context](const fs::path& dir) {
                     context(dir);
                     Exr exr = read_exr(source);
                     mutate(exr);
                     write_exr(dir / "p0.blend.exr", exr);
                   },
                   args,
                   "out",
                   {"p0.blend.exr"}});
  };
  add_exr("pixel_nan", [](Exr& e) { e.pixels[100] = std::numeric_limits<float>::quiet_NaN(); });
  add_exr("pixel_inf", [](Exr& e) { e.pixels[100] = std::numeric_limits<float>::infinity(); });
  add_exr("pixel_negative", [](Exr& e) { e.pixels[100] = -1.0f; });
  add_exr("wrong_size", [](Exr& e) {
    e.width = 512;
    e.height = 256;
    e.pixels.resize(512 * 256);
  });
  add_exr("two_channels", [](Exr& e) {
    std::vector<float> rg;
    for (const float v : e.pixels) rg.insert(rg.end(), {v, v});
    e.pixels = rg;
    e.channels = {"R", "G"};
  });
  add_exr("meta_not_json", [](Exr& e) { e.attributes = {{"facet:blend", "{["}}; });
  add_exr("meta_format_unknown", [](Exr& e) {
    e.attributes = {{"facet:blend", "{\"format\":\"facet-blend/7\"}"}};
  });
  out.push_back({"blend_exr_data_window_huge",
                 [source, context](const fs::path& dir) {
                   context(dir);
                   spit(dir / "p0.blend.exr",
                        exr_with_data_window(slurp(source), 1 << 30, 1 << 30));
                 },
                 args,
                 "out",
                 {"p0.blend.exr"}});
  out.push_back({"blend_exr_warp_given_as_blend",
                 [context](const fs::path& dir) {
                   context(dir);
                   fs::copy_file(kSource / "configs/displays/cylinder3/p0.warp.exr",
                                 dir / "p0.blend.exr");
                 },
                 args,
                 "out",
                 {"p0.blend.exr"}});
}

// Rig JSON: configs/rigs/wall2x2.json, through facet simulate.
json rig_base() { return json::parse(slurp(kSource / "configs/rigs/wall2x2.json")); }

void add_rig_json(std::vector<Variant>& out) {
  const std::vector<std::string> args{"simulate", "--rig",         "@rig.json", "--out",
                                      "@out",     "--camera-size", "64x48"};
  add_byte_variants(
      out, "rig_json", [] { return rig_base().dump(1); }, "rig.json", nullptr, args, "out",
      {0.001, 0.3, 0.6, 0.999}, false);
  add_non_regular_variants(out, "rig_json", "rig.json", nullptr, args, "out");
  std::vector<FieldMutation> m = {
      {"format_unknown", "/format", "\"facet-rig/9\"", "format"},
      {"format_missing", "/format", "", "format"},
      {"screen_type_bogus", "/screen/type", "\"banana\"", "type"},
      {"normal_zero", "/screen/normal", "[0, 0, 0]", "normal"},
      {"normal_nan", "/screen/normal", "[NaN, 0, 1]", "normal"},
      {"point_short", "/screen/point", "[0, 0]", "point"},
      {"projectors_empty", "/projectors", "[]", "projectors"},
      {"projectors_string", "/projectors", "\"p0\"", "projectors"},
      {"size_negative", "/projectors/0/size", "[-1024, 576]", "size"},
      {"size_zero", "/projectors/0/size", "[0, 576]", "size"},
      {"size_huge", "/projectors/0/size", "[100000000, 100000000]", "size"},
      {"size_1e308", "/projectors/0/size", "[1e308, 576]", "size"},
      {"fov_zero", "/projectors/0/fov_deg", "0", "fov_deg"},
      {"fov_negative", "/projectors/0/fov_deg", "-70", "fov_deg"},
      {"fov_180", "/projectors/0/fov_deg", "180", "fov_deg"},
      {"fov_inf", "/projectors/0/fov_deg", "1e999", "fov_deg"},
      {"fov_string", "/projectors/0/fov_deg", "\"70\"", "fov_deg"},
      {"distortion_string", "/projectors/0/distortion", "\"none\"", "distortion"},
      {"gamma_zero", "/projectors/0/gamma", "0", "gamma"},
      {"gamma_negative", "/projectors/0/gamma", "-2.2", "gamma"},
      {"t_eye_projector_short", "/projectors/0/t_eye_projector", "[0.3]", "t_eye_projector"},
      {"look_at_at_projector", "/projectors/0/look_at", "[-0.3, 0.2, 0.5]", "look_at"},
      {"up_zero", "/projectors/0/up", "[0, 0, 0]", "up"},
      {"name_duplicate", "/projectors/1/name", "\"p0\"", "name"},
      {"name_path_escape", "/projectors/0/name", "\"../../escape\"", "name"},
      {"name_invalid_utf8", "/projectors/0/name", "\"\xc3\x28\"", "name"},
      {"unknown_key", "/projectors/0/surprise", "true", "surprise"},
  };
  add_json_variants(out, "rig_json", rig_base, "rig.json", nullptr, m, args, "out");
}

// GLC camera: configs/glc/city_cross_slit.glc.json, through facet render --method glc.
json glc_base() { return json::parse(slurp(kSource / "configs/glc/city_cross_slit.glc.json")); }

void add_glc_json(std::vector<Variant>& out) {
  const std::vector<std::string> args{"render", "--display", "@camera.glc.json", "--method", "glc",
                                      "--out",  "@out"};
  add_byte_variants(
      out, "glc_json", [] { return glc_base().dump(1); }, "camera.glc.json", nullptr, args, "out",
      {0.001, 0.3, 0.6, 0.999}, false);
  add_non_regular_variants(out, "glc_json", "camera.glc.json", nullptr, args, "out");
  std::vector<FieldMutation> m = {
      {"format_unknown", "/format", "\"facet-glc/9\"", "format"},
      {"format_missing", "/format", "", "format"},
      {"camera_string", "/camera", "\"cross-slit\"", "camera"},
      {"type_bogus", "/camera/type", "\"fisheye\"", "type"},
      {"type_number", "/camera/type", "3", "type"},
      {"size_zero", "/camera/size", "[0, 320]", "size"},
      {"size_negative", "/camera/size", "[-1024, 320]", "size"},
      {"size_huge", "/camera/size", "[100000, 100000]", "size"},
      {"size_1e308", "/camera/size", "[1e308, 320]", "size"},
      {"size_short", "/camera/size", "[1024]", "size"},
      {"plane_size_zero", "/camera/plane_size", "[0, 2]", "plane_size"},
      {"plane_size_negative", "/camera/plane_size", "[3.2, -2]", "plane_size"},
      {"slit1_missing", "/camera/slit1", "", "slit1"},
      {"slit1_direction_zero", "/camera/slit1/direction", "[0, 0, 0]", "slit1"},
      {"slit1_point_short", "/camera/slit1/point", "[0, 0]", "point"},
      {"slits_parallel", "/camera/slit2/direction", "[0, 2, 0]", "slit2"},
      {"slits_meet", "/camera/slit2/point", "[0, 0, -1]", "slit2"},
      {"slit_through_plane_corner", "/camera/slit1/point", "[-1.6, -1, 0]", "slit1"},
      {"look_at_origin", "/camera/frame/look_at", "[0, 0, 0]", "look_at"},
      {"up_along_view", "/camera/frame/up", "[0, 0, -1]", "up"},
      {"unknown_key", "/camera/surprise", "true", "surprise"},
  };
  add_json_variants(out, "glc_json", glc_base, "camera.glc.json", nullptr, m, args, "out");
}

// capture.json and camera.cameramodel: the real procam-board capture, images linked in.
const fs::path kCapture = kShared / "captures/procam-board";

json capture_base() { return json::parse(slurp(kCapture / "capture.json")); }

void capture_context(const fs::path& dir) {
  fs::create_directories(dir / "cap");
  for (const auto& entry : fs::directory_iterator(kCapture)) {
    const std::string name = entry.path().filename().string();
    if (name == "capture.json" || name == "camera.cameramodel") continue;
    fs::create_symlink(entry.path(), dir / "cap" / name);
  }
  fs::copy_file(kCapture / "camera.cameramodel", dir / "cap/camera.cameramodel");
}

void add_capture(std::vector<Variant>& out) {
  const std::vector<std::string> args{"calibrate", "@cap", "--out", "@out"};
  auto context = [](const fs::path& dir) { capture_context(dir); };
  add_byte_variants(
      out, "capture_json", [] { return capture_base().dump(1); }, "cap/capture.json", context, args,
      "out", {0.001, 0.3, 0.6, 0.999}, false);
  add_non_regular_variants(out, "capture_json", "cap/capture.json", context, args, "out");
  std::vector<FieldMutation> m = {
      {"format_unknown", "/format", "\"facet-capture/9\"", "format"},
      {"camera_missing", "/camera", "", "camera"},
      {"model_missing_file", "/camera/model", "\"nowhere.cameramodel\"", "nowhere"},
      {"model_directory", "/camera/model", "\".\"", "model"},
      {"model_dev_null", "/camera/model", "\"/dev/null\"", "null"},
      {"R_zero", "/camera/R_eye_camera", "[[0,0,0],[0,0,0],[0,0,0]]", "R_eye_camera"},
      {"R_nan", "/camera/R_eye_camera/0/0", "NaN", "R_eye_camera"},
      {"R_short", "/camera/R_eye_camera", "[[1,0,0]]", "R_eye_camera"},
      {"t_string", "/camera/t_eye_camera", "\"origin\"", "t_eye_camera"},
      {"projectors_empty", "/projectors", "[]", "projectors"},
      {"size_negative", "/projectors/0/size", "[-1024, 768]", "size"},
      {"size_zero", "/projectors/0/size", "[0, 0]", "size"},
      {"size_huge", "/projectors/0/size", "[2000000000, 2000000000]", "size"},
      {"gamma_zero", "/projectors/0/gamma", "0", "gamma"},
      {"frames_empty", "/projectors/0/frames", "[]", "frames"},
      {"frame_file_missing", "/projectors/0/frames/0/file", "\"nowhere.png\"", "nowhere"},
      {"frame_file_escape", "/projectors/0/frames/0/file", "\"../../../../../../etc/passwd\"",
       "passwd"},
      {"frame_file_fifo_dev", "/projectors/0/frames/0/file", "\"/dev/zero\"", "/dev/zero"},
      {"pattern_type_bogus", "/projectors/0/frames/0/pattern/type", "\"plaid\"", "type"},
      {"pattern_axis_bogus", "/projectors/0/frames/0/pattern/axis", "\"w\"", "axis"},
      {"pattern_bit_huge", "/projectors/0/frames/0/pattern/bit", "4294967296", "bit"},
      {"pattern_bit_negative", "/projectors/0/frames/0/pattern/bit", "-1", "bit"},
      {"name_invalid_utf8", "/projectors/0/name", "\"\xed\xa0\x80\"", "name"},
  };
  add_json_variants(out, "capture_json", capture_base, "cap/capture.json", context, m, args, "out");
  // A frame image truncated.
  out.push_back({"capture_png_truncated",
                 [](const fs::path& dir) {
                   capture_context(dir);
                   fs::remove(dir / "cap/graycode_00.png");
                   spit(dir / "cap/graycode_00.png",
                        truncated(slurp(kCapture / "graycode_00.png"), 5000));
                   spit(dir / "cap/capture.json", capture_base().dump(1));
                 },
                 args,
                 "out",
                 {"graycode_00.png"}});
  out.push_back({"capture_png_wrong_size",
                 [](const fs::path& dir) {
                   capture_context(dir);
                   fs::remove(dir / "cap/graycode_00.png");
                   fs::copy_file(kShared / "warps/sgct-dome/sciss/channel1.png",
                                 dir / "cap/graycode_00.png");
                   spit(dir / "cap/capture.json", capture_base().dump(1));
                 },
                 args,
                 "out",
                 {"graycode_00.png"}});
  // Frame images whose header asks for more than the file holds (the fuzz corpus's seeds): an
  // OpenEXR attribute of 2 GB in 1 KB, a channel list whose size disagrees with its content (both
  // allocated by OpenEXR unless the header is checked first), an EXR data window of 2^30 x 2^30
  // and a PNG of 100000 x 100000.
  for (const auto& [variant, seed] : std::vector<std::pair<std::string, std::string>>{
           {"capture_exr_attribute_2gb", "attribute_of_2gb.warp.exr"},
           {"capture_exr_chlist_size_disagrees", "chlist_size_disagrees.warp.exr"},
           {"capture_exr_data_window_huge", "data_window_huge.warp.exr"},
           {"capture_png_huge_header", "huge_header.png"}}) {
    const std::string frame = seed.ends_with(".png") ? "graycode_00.png" : "graycode_00.exr";
    out.push_back({variant,
                   [seed, frame](const fs::path& dir) {
                     capture_context(dir);
                     fs::remove(dir / "cap/graycode_00.png");
                     fs::copy_file(kSource / "tests/fuzz/corpus" / seed, dir / "cap" / frame);
                     json capture = capture_base();
                     capture["projectors"][0]["frames"][0]["file"] = frame;
                     spit(dir / "cap/capture.json", capture.dump(1));
                   },
                   args,
                   "out",
                   {frame}});
  }

  // The camera model (mrcal's Python-literal format) inside the capture.
  const std::string model = slurp(kCapture / "camera.cameramodel");
  auto with_model = [](std::string text) {
    return [text](const fs::path& dir) {
      capture_context(dir);
      spit(dir / "cap/capture.json", capture_base().dump(1));
      fs::remove(dir / "cap/camera.cameramodel");
      spit(dir / "cap/camera.cameramodel", text);
    };
  };
  auto add_model = [&](const std::string& what, const std::string& text) {
    out.push_back({"cameramodel_" + what,
                   with_model(text),
                   args,
                   "out",
                   {"camera.cameramodel", "camera.model"}});
  };
  add_model("empty", "");
  for (const std::size_t at :
       {std::size_t{20}, model.size() / 3, model.size() / 2, model.size() - 30}) {
    add_model("truncated_" + std::to_string(at), truncated(model, at));
  }
  add_model("lensmodel_unknown", replace_first(model, "LENSMODEL_OPENCV5", "LENSMODEL_BOGUS"));
  add_model("lensmodel_number", replace_first(model, "'LENSMODEL_OPENCV5'", "5"));
  add_model("intrinsics_short",
            replace_first(model, "3452.392907, 3449.924293, 587.1731473, 521.4460257, ", ""));
  add_model("intrinsics_nan", replace_first(model, "3452.392907", "nan"));
  add_model("intrinsics_inf", replace_first(model, "3452.392907", "1e999"));
  add_model("focal_zero", replace_first(model, "3452.392907", "0"));
  add_model("focal_negative", replace_first(model, "3452.392907", "-3452.392907"));
  add_model("intrinsics_string", replace_first(model, "3452.392907", "'fx'"));
  add_model("imagersize_negative", replace_first(model, "[ 1280, 1024,]", "[ -1280, 1024,]"));
  add_model("imagersize_zero", replace_first(model, "[ 1280, 1024,]", "[ 0, 0,]"));
  add_model("imagersize_huge",
            replace_first(model, "[ 1280, 1024,]", "[ 2000000000, 2000000000,]"));
  add_model("imagersize_mismatch", replace_first(model, "[ 1280, 1024,]", "[ 640, 512,]"));
  add_model("extrinsics_short", replace_first(model, "[ 0, 0, 0, 0, 0, 0,]", "[ 0, 0,]"));
  add_model("unbalanced_brace", replace_first(model, "}", ""));
  add_model("deeply_nested",
            "{ 'lensmodel': " + std::string(100000, '[') + std::string(100000, ']') + "}");
  add_model("invalid_utf8", replace_first(model, "LENSMODEL_OPENCV5", "LENSMODEL_\xff\xfe"));
  add_model("binary_garbage", std::string(2000, '\x9c'));
  add_model("unterminated_string",
            replace_first(model, "'LENSMODEL_OPENCV5'", "'LENSMODEL_OPENCV5"));
  out.push_back({"cameramodel_directory",
                 [](const fs::path& dir) {
                   capture_context(dir);
                   spit(dir / "cap/capture.json", capture_base().dump(1));
                   fs::remove(dir / "cap/camera.cameramodel");
                   fs::create_directories(dir / "cap/camera.cameramodel");
                 },
                 args,
                 "out",
                 {"camera.cameramodel"}});
  out.push_back({"cameramodel_fifo",
                 [](const fs::path& dir) {
                   capture_context(dir);
                   spit(dir / "cap/capture.json", capture_base().dump(1));
                   fs::remove(dir / "cap/camera.cameramodel");
                   ::mkfifo((dir / "cap/camera.cameramodel").c_str(), 0644);
                 },
                 args,
                 "out",
                 {"camera.cameramodel"}});
}

// MPCDI: the real correction_mesh.mpcdi (mpcdi1_.xml and surface1.pfm), rewritten.
const fs::path kMpcdi = kShared / "warps/sgct-mpcdi/correction_mesh.mpcdi";

Entries mpcdi_entries() { return read_zip(kMpcdi); }

std::string& entry(Entries& entries, const std::string& suffix) {
  for (auto& [name, data] : entries) {
    if (name.ends_with(suffix)) return data;
  }
  static std::string none;
  return none;
}

void add_mpcdi(std::vector<Variant>& out) {
  const std::vector<std::string> args{"mpcdi", "import", "@x.mpcdi", "--out", "@out"};
  add_byte_variants(
      out, "mpcdi", [] { return slurp(kMpcdi); }, "x.mpcdi", nullptr, args, "out",
      {0.001, 0.1, 0.5, 0.9, 0.999}, false);
  add_non_regular_variants(out, "mpcdi", "x.mpcdi", nullptr, args, "out");
  auto add_zip = [&](const std::string& what, std::function<void(Entries&)> mutate,
                     const std::string& mention = "x.mpcdi") {
    out.push_back({"mpcdi_" + what,
                   [mutate](const fs::path& dir) {
                     Entries entries = mpcdi_entries();
                     mutate(entries);
                     write_zip(dir / "x.mpcdi", entries);
                   },
                   args,
                   "out",
                   {"x.mpcdi", mention}});
  };
  auto xml = [](const std::function<std::string(std::string)>& edit) {
    return [edit](Entries& e) {
      std::string& text = entry(e, ".xml");
      text = edit(text);
    };
  };
  auto xml_replace = [&](const std::string& from, const std::string& to) {
    return xml([from, to](std::string t) { return replace_first(t, from, to); });
  };
  add_zip("empty_zip", [](Entries& e) { e.clear(); });
  add_zip("no_xml", [](Entries& e) { e.erase(e.begin()); });
  add_zip(
      "no_pfm", [](Entries& e) { e.pop_back(); }, "surface1.pfm");
  add_zip("xml_entity_bomb", xml([](std::string) { return entity_bomb("MPCDI"); }));
  add_zip("xml_deeply_nested", xml([](std::string) { return deep_xml("MPCDI"); }));
  add_zip("xml_truncated", xml([](std::string t) { return t.substr(0, t.size() / 2); }));
  add_zip("xml_invalid_utf8", xml_replace("surface1_region\"", "surface1_\xff\xfe\""));
  add_zip(
      "xml_external_entity", xml([](std::string t) {
        return replace_first(
            replace_first(t, "<MPCDI", "<!DOCTYPE m [<!ENTITY x SYSTEM \"/etc/passwd\">]>\n<MPCDI"),
            "<path>surface1.pfm</path>", "<path>&x;</path>");
      }));
  add_zip("resolution_negative", xml_replace("xResolution=\"512\"", "xResolution=\"-512\""),
          "xResolution");
  add_zip("resolution_zero", xml_replace("xResolution=\"512\"", "xResolution=\"0\""),
          "xResolution");
  add_zip("resolution_huge", xml_replace("xResolution=\"512\"", "xResolution=\"2000000000\""),
          "xResolution");
  add_zip("resolution_text", xml_replace("xResolution=\"512\"", "xResolution=\"wide\""),
          "xResolution");
  add_zip("angle_nan", xml_replace("<rightAngle>33.231552", "<rightAngle>nan"), "rightAngle");
  add_zip("angle_inf", xml_replace("<rightAngle>33.231552", "<rightAngle>inf"), "rightAngle");
  add_zip("angle_text", xml_replace("<rightAngle>33.231552", "<rightAngle>wide"), "rightAngle");
  add_zip("angles_inverted", xml_replace("<rightAngle>33.231552", "<rightAngle>-40"), "Angle");
  add_zip("yaw_huge", xml_replace("<yaw>326.675157", "<yaw>1e308"), "yaw");
  add_zip("path_zip_slip", xml_replace("<path>surface1.pfm", "<path>../../../../etc/passwd"),
          "passwd");
  add_zip("path_absolute", xml_replace("<path>surface1.pfm", "<path>/etc/passwd"), "passwd");
  add_zip("path_missing_entry", xml_replace("<path>surface1.pfm", "<path>nowhere.pfm"), "nowhere");
  add_zip("path_empty", xml_replace("<path>surface1.pfm", "<path>"), "path");
  add_zip("profile_bogus", xml_replace("profile=\"3d\"", "profile=\"9z\""), "profile");
  add_zip("region_unmatched", xml_replace("region=\"surface1_region\"", "region=\"elsewhere\""),
          "elsewhere");
  // PFM inside the container (interop/src/pfm.cpp).
  auto pfm = [&](const std::string& what, std::function<std::string(std::string)> edit) {
    add_zip(
        "pfm_" + what,
        [edit](Entries& e) {
          std::string& data = entry(e, ".pfm");
          data = edit(data);
        },
        "surface1.pfm");
  };
  const std::size_t header = std::string("PF\n32 32\n-1.000\n").size();
  pfm("empty", [](std::string) { return std::string(); });
  pfm("truncated_header", [](std::string d) { return d.substr(0, 5); });
  pfm("truncated_data", [](std::string d) { return d.substr(0, d.size() / 2); });
  pfm("truncated_one_float", [](std::string d) { return d.substr(0, d.size() - 4); });
  pfm("magic_bogus", [](std::string d) { return "PX" + d.substr(2); });
  pfm("greyscale_magic", [](std::string d) { return "Pf" + d.substr(2); });
  pfm("size_huge",
      [header](std::string d) { return "PF\n2000000000 2000000000\n-1.000\n" + d.substr(header); });
  pfm("size_overflow",
      [header](std::string d) { return "PF\n4294967297 4294967297\n-1.000\n" + d.substr(header); });
  pfm("size_negative",
      [header](std::string d) { return "PF\n-32 32\n-1.000\n" + d.substr(header); });
  pfm("size_zero", [header](std::string d) { return "PF\n0 0\n-1.000\n" + d.substr(header); });
  pfm("size_text", [header](std::string d) { return "PF\nab cd\n-1.000\n" + d.substr(header); });
  pfm("scale_zero", [header](std::string d) { return "PF\n32 32\n0\n" + d.substr(header); });
  pfm("scale_nan", [header](std::string d) { return "PF\n32 32\nnan\n" + d.substr(header); });
  pfm("all_inf", [header](std::string d) {
    const float inf = std::numeric_limits<float>::infinity();
    for (std::size_t at = header; at + 4 <= d.size(); at += 4)
      d.replace(at, 4, reinterpret_cast<const char*>(&inf), 4);
    return d;
  });
  pfm("all_nan", [header](std::string d) {
    const float nan = std::numeric_limits<float>::quiet_NaN();
    for (std::size_t at = header; at + 4 <= d.size(); at += 4)
      d.replace(at, 4, reinterpret_cast<const char*>(&nan), 4);
    return d;
  });
  pfm("scale_missing", [header](std::string d) { return "PF\n32 32\n" + d.substr(header); });
  pfm("scale_text", [header](std::string d) { return "PF\n32 32\nabc\n" + d.substr(header); });
  pfm("scale_inf", [header](std::string d) { return "PF\n32 32\n-1e999\n" + d.substr(header); });
  pfm("size_one_number", [header](std::string d) { return "PF\n32\n-1.000\n" + d.substr(header); });
  pfm("size_larger_than_data",
      [header](std::string d) { return "PF\n33 32\n-1.000\n" + d.substr(header); });
  pfm("size_wide_and_flat",
      [header](std::string d) { return "PF\n100000000 1\n-1.000\n" + d.substr(header); });
  pfm("header_invalid_utf8",
      [header](std::string d) { return "\xff\xfe\n32 32\n-1.000\n" + d.substr(header); });
  pfm("header_only", [header](std::string d) { return d.substr(0, header); });
  // A 600 MB entry of zeros compressed to well under a megabyte.
  out.push_back({"mpcdi_zip_bomb_pfm",
                 [](const fs::path& dir) {
                   Entries entries = mpcdi_entries();
                   entries.pop_back();
                   write_zip_bomb(dir / "x.mpcdi", entries, "surface1.pfm", 600u << 20);
                 },
                 args,
                 "out",
                 {"x.mpcdi", "surface1.pfm"}});
}

// Bourke .data: the real standard_16x9.data mesh.
const fs::path kBourke = kShared / "warps/sgct-mesh/standard_16x9.data";

void add_bourke(std::vector<Variant>& out) {
  const std::vector<std::string> args{"bourke", "import", "@x.data", "--out", "@out"};
  add_byte_variants(out, "bourke", [] { return slurp(kBourke); }, "x.data", nullptr, args, "out",
                    {0.001, 0.005, 0.5, 0.999});
  add_non_regular_variants(out, "bourke", "x.data", nullptr, args, "out");
  auto add = [&](const std::string& what, std::function<std::string(std::string)> edit) {
    out.push_back({"bourke_" + what,
                   [edit](const fs::path& dir) { spit(dir / "x.data", edit(slurp(kBourke))); },
                   args,
                   "out",
                   {"x.data"}});
  };
  auto head = [](std::string d, const std::string& second_line) {
    const std::size_t one = d.find('\n');
    const std::size_t two = d.find('\n', one + 1);
    return d.substr(0, one + 1) + second_line + d.substr(two);
  };
  add("type_unknown", [](std::string d) { return d.replace(0, d.find('\n'), "7"); });
  add("type_text", [](std::string d) { return d.replace(0, d.find('\n'), "mesh"); });
  add("size_negative", [head](std::string d) { return head(d, "-100 60"); });
  add("size_zero", [head](std::string d) { return head(d, "0 0"); });
  add("size_one", [head](std::string d) { return head(d, "1 1"); });
  add("size_huge", [head](std::string d) { return head(d, "2000000000 2000000000"); });
  add("size_overflow", [head](std::string d) { return head(d, "4294967296 4294967296"); });
  add("size_text", [head](std::string d) { return head(d, "a b"); });
  add("size_more_than_rows", [head](std::string d) { return head(d, "100 61"); });
  add("x_nan", [](std::string d) { return replace_first(d, "-1.77778\t-1\t", "nan\t-1\t"); });
  add("x_inf", [](std::string d) { return replace_first(d, "-1.77778\t-1\t", "inf\t-1\t"); });
  add("intensity_nan", [](std::string d) { return replace_first(d, "\t0.530521", "\tnan"); });
  add("row_short", [](std::string d) { return replace_first(d, "\t0.86737\t0.530521", ""); });
  add("row_text", [](std::string d) { return replace_first(d, "-1.74186", "abc"); });
  add("invalid_utf8", [](std::string d) { return replace_first(d, "-1.74186", "\xff\xfe"); });
  add("nul_bytes",
      [](std::string d) { return replace_first(d, "-1.74186", std::string(8, '\0')); });
  add("duplicate_rows", [](std::string d) {
    const std::size_t two = d.find('\n', d.find('\n') + 1) + 1;
    const std::size_t row_end = d.find('\n', two) + 1;
    return d.substr(0, two) + d.substr(two, row_end - two) +
           d.substr(two, d.rfind('\n', d.size() - 2) + 1 - two);
  });
}

// SGC: the real SCISS channel1_planar.sgc (version 2) through facet sgct import.
const fs::path kSgc = kShared / "warps/sgct-dome/sciss/channel1_planar.sgc";

void add_sgc(std::vector<Variant>& out) {
  const std::vector<std::string> args{"sgct", "import", "@x.sgc", "--out", "@out"};
  add_byte_variants(out, "sgc", [] { return slurp(kSgc); }, "x.sgc", nullptr, args, "out",
                    {0.0001, 0.001, 0.05, 0.5, 0.999});
  add_non_regular_variants(out, "sgc", "x.sgc", nullptr, args, "out");
  // Header: "SGC" (3), version (1), type (4), 11 floats (44), two uint32 (8): 60 bytes; then
  // vertices of 6 floats, then the index count and the indices.
  auto add = [&](const std::string& what, std::function<std::string(std::string)> edit) {
    out.push_back({"sgc_" + what,
                   [edit](const fs::path& dir) { spit(dir / "x.sgc", edit(slurp(kSgc))); },
                   args,
                   "out",
                   {"x.sgc"}});
  };
  auto put_u32 = [](std::string d, std::size_t at, std::uint32_t v) {
    if (at + 4 <= d.size()) d.replace(at, 4, reinterpret_cast<const char*>(&v), 4);
    return d;
  };
  auto put_f32 = [](std::string d, std::size_t at, float v) {
    if (at + 4 <= d.size()) d.replace(at, 4, reinterpret_cast<const char*>(&v), 4);
    return d;
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  add("version_unknown", [](std::string d) {
    d[3] = 9;
    return d;
  });
  add("type_unknown", [put_u32](std::string d) { return put_u32(d, 4, 7); });
  add("quaternion_nan", [=](std::string d) { return put_f32(d, 8, nan); });
  add("quaternion_zero", [=](std::string d) {
    for (int i = 0; i < 4; ++i) d = put_f32(d, 8 + 4 * i, 0.0f);
    return d;
  });
  add("fov_inf", [=](std::string d) { return put_f32(d, 36, inf); });
  add("fov_zero", [=](std::string d) {
    for (int i = 0; i < 4; ++i) d = put_f32(d, 36 + 4 * i, 0.0f);
    return d;
  });
  add("fov_nan", [=](std::string d) { return put_f32(d, 40, nan); });
  add("vertex_count_huge", [put_u32](std::string d) { return put_u32(d, 56, 0xfffffff0u); });
  add("vertex_count_zero", [put_u32](std::string d) { return put_u32(d, 56, 0); });
  add("count_fields_huge",
      [put_u32](std::string d) { return put_u32(put_u32(d, 52, 0xffffffffu), 56, 0xffffffffu); });
  add("vertex_nan", [=](std::string d) { return put_f32(put_f32(d, 60, nan), 64, nan); });
  add("vertex_inf", [=](std::string d) { return put_f32(d, 60 + 12, inf); });
  add("index_count_huge", [put_u32](std::string d) {
    std::uint32_t vertices = 0;
    if (d.size() >= 60) std::memcpy(&vertices, d.data() + 56, 4);
    return put_u32(d, 60 + static_cast<std::size_t>(vertices) * 24, 0xfffffff0u);
  });
  add("index_out_of_range", [put_u32](std::string d) {
    std::uint32_t vertices = 0;
    if (d.size() >= 60) std::memcpy(&vertices, d.data() + 56, 4);
    return put_u32(d, 64 + static_cast<std::size_t>(vertices) * 24, 0x7fffffffu);
  });
  add("trailing_bytes", [](std::string d) { return d + std::string(13, '\x7f'); });
}

// SGCT cluster XML and .simcad: the real dome_alpha.xml (with .sgc meshes and .png masks) and
// dome_bravo.xml (with .simcad meshes and frustum CSVs), the files linked in.
const fs::path kAlpha = kShared / "warps/sgct-dome/sciss";
const fs::path kBravo = kShared / "warps/sgct-dome/simcad";

void add_cluster(std::vector<Variant>& out) {
  const std::vector<std::string> alpha{"sgct", "import", "@c/dome_alpha.xml", "--out", "@out"};
  auto alpha_context = [](const fs::path& dir) { link_all(kAlpha, dir / "c", "dome_alpha.xml"); };
  add_byte_variants(
      out, "cluster_xml", [] { return slurp(kAlpha / "dome_alpha.xml"); }, "c/dome_alpha.xml",
      alpha_context, alpha, "out", {0.001, 0.2, 0.5, 0.95}, false);
  add_non_regular_variants(out, "cluster_xml", "c/dome_alpha.xml", alpha_context, alpha, "out");
  auto add = [&](const std::string& what, std::function<std::string(std::string)> edit,
                 const std::string& mention = "dome_alpha.xml") {
    out.push_back({"cluster_xml_" + what,
                   [edit, alpha_context](const fs::path& dir) {
                     alpha_context(dir);
                     spit(dir / "c/dome_alpha.xml", edit(slurp(kAlpha / "dome_alpha.xml")));
                   },
                   alpha,
                   "out",
                   {"dome_alpha.xml", mention}});
  };
  add("entity_bomb", [](std::string) { return entity_bomb("Cluster"); });
  add("deeply_nested", [](std::string) { return deep_xml("Cluster"); });
  add(
      "size_negative",
      [](std::string t) { return replace_first(t, "<Size x=\"1280\"", "<Size x=\"-1280\""); },
      "Size");
  add(
      "size_huge",
      [](std::string t) { return replace_first(t, "<Size x=\"1280\"", "<Size x=\"2000000000\""); },
      "Size");
  add(
      "size_text",
      [](std::string t) { return replace_first(t, "<Size x=\"1280\"", "<Size x=\"wide\""); },
      "Size");
  add(
      "mesh_zip_slip",
      [](std::string t) {
        return replace_first(t, "channel1_planar.sgc", "../../../../../etc/passwd");
      },
      "passwd");
  add(
      "mesh_missing",
      [](std::string t) { return replace_first(t, "channel1_planar.sgc", "nowhere.sgc"); },
      "nowhere");
  add(
      "mesh_dev_zero",
      [](std::string t) { return replace_first(t, "channel1_planar.sgc", "/dev/zero"); }, "zero");
  add(
      "mask_missing", [](std::string t) { return replace_first(t, "channel1.png", "nowhere.png"); },
      "nowhere");
  add(
      "mask_directory", [](std::string t) { return replace_first(t, "channel1.png", "."); },
      "mask");
  add("no_nodes", [](std::string) { return std::string("<?xml version=\"1.0\"?>\n<Cluster/>\n"); });
  add("wrong_root",
      [](std::string) { return std::string("<?xml version=\"1.0\"?>\n<Display/>\n"); });
  out.push_back({"cluster_mask_truncated_png",
                 [alpha_context](const fs::path& dir) {
                   link_all(kAlpha, dir / "c", "channel1.png");
                   spit(dir / "c/channel1.png", truncated(slurp(kAlpha / "channel1.png"), 3000));
                 },
                 alpha,
                 "out",
                 {"channel1.png"}});
  out.push_back({"cluster_mesh_truncated_sgc",
                 [](const fs::path& dir) {
                   link_all(kAlpha, dir / "c", "channel1_planar.sgc");
                   spit(dir / "c/channel1_planar.sgc",
                        truncated(slurp(kAlpha / "channel1_planar.sgc"), 1000));
                 },
                 alpha,
                 "out",
                 {"channel1_planar"}});

  // .simcad meshes (and their frustum CSVs) through dome_bravo.xml.
  const std::vector<std::string> bravo{"sgct", "import", "@c/dome_bravo.xml", "--out", "@out"};
  const std::string simcad = "channel1_warp.simcad";
  auto bravo_context = [simcad](const fs::path& dir) { link_all(kBravo, dir / "c", simcad); };
  add_byte_variants(
      out, "simcad", [simcad] { return slurp(kBravo / simcad); }, "c/" + simcad, bravo_context,
      bravo, "out", {0.001, 0.05, 0.5, 0.99}, false);
  auto add_simcad = [&](const std::string& what, std::function<std::string(std::string)> edit) {
    out.push_back({"simcad_" + what,
                   [edit, bravo_context, simcad](const fs::path& dir) {
                     bravo_context(dir);
                     spit(dir / "c" / simcad, edit(slurp(kBravo / simcad)));
                   },
                   bravo,
                   "out",
                   {simcad}});
  };
  add_simcad("entity_bomb", [](std::string) { return entity_bomb("GeometryFile"); });
  // One channel's mesh missing: its viewport is named, not left out of the display.
  out.push_back({"simcad_missing",
                 [](const fs::path& dir) { link_all(kBravo, dir / "c", "channel1_warp.simcad"); },
                 bravo,
                 "out",
                 {"dome_bravo.xml", "Viewport"}});
  add_simcad("deeply_nested", [](std::string) { return deep_xml("GeometryFile"); });
  add_simcad("range_zero",
             [](std::string t) { return replace_first(t, "range=\"2560\"", "range=\"0\""); });
  add_simcad("range_nan",
             [](std::string t) { return replace_first(t, "range=\"2560\"", "range=\"nan\""); });
  add_simcad("value_nan",
             [](std::string t) { return replace_first(t, "496.60932920343123", "nan"); });
  add_simcad("value_inf",
             [](std::string t) { return replace_first(t, "496.60932920343123", "inf"); });
  add_simcad("value_text",
             [](std::string t) { return replace_first(t, "496.60932920343123", "abc"); });
  add_simcad("one_value_fewer",
             [](std::string t) { return replace_first(t, "496.60932920343123 ", ""); });
  add_simcad("one_value_more",
             [](std::string t) { return replace_first(t, "496.60932920343123 ", "1 496.6 "); });
  add_simcad("no_y_parameters",
             [](std::string t) { return replace_all(t, "Y-FlatParameters", "Z-FlatParameters"); });
  add_simcad("invalid_utf8",
             [](std::string t) { return replace_first(t, "496.60932920343123", "\xff\xfe"); });
  // The frustum CSV beside it.
  auto add_frustum = [&](const std::string& what, std::function<std::string(std::string)> edit) {
    out.push_back({"simcad_frustum_" + what,
                   [edit](const fs::path& dir) {
                     link_all(kBravo, dir / "c", "channel1_warp_frustum.csv");
                     spit(dir / "c/channel1_warp_frustum.csv",
                          edit(slurp(kBravo / "channel1_warp_frustum.csv")));
                   },
                   bravo,
                   "out",
                   {"channel1_warp_frustum.csv"}});
  };
  add_frustum("empty", [](std::string) { return std::string(); });
  add_frustum("truncated", [](std::string t) { return t.substr(0, t.size() / 2); });
  add_frustum("binary_garbage", [](std::string t) { return std::string(t.size(), '\xfe'); });
}

// glTF: a unit square (positions, indices) with its buffer in square.bin beside it, rendered
// into a tiny built-in dome.
json gltf_base() {
  return json::parse(R"({
  "asset": {"version": "2.0"},
  "scene": 0,
  "scenes": [{"nodes": [0]}],
  "nodes": [{"name": "square", "mesh": 0, "children": [1]}, {"name": "child", "mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
  "accessors": [
    {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
     "min": [0, 0, 0], "max": [1, 1, 0]},
    {"bufferView": 1, "componentType": 5123, "count": 6, "type": "SCALAR"}
  ],
  "bufferViews": [
    {"buffer": 0, "byteOffset": 0, "byteLength": 48},
    {"buffer": 0, "byteOffset": 48, "byteLength": 12}
  ],
  "buffers": [{"byteLength": 60, "uri": "square.bin"}]
})");
}

std::string gltf_buffer() {
  std::string bytes;
  const float positions[4][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  bytes.append(reinterpret_cast<const char*>(positions), sizeof positions);
  const std::uint16_t indices[6] = {0, 1, 2, 0, 2, 3};
  bytes.append(reinterpret_cast<const char*>(indices), sizeof indices);
  return bytes;
}

void gltf_context(const fs::path& dir) { spit(dir / "square.bin", gltf_buffer()); }

void add_gltf(std::vector<Variant>& out) {
  const std::vector<std::string> args{"render",  "--display", "builtin:dome180", "--size", "32x32",
                                      "--scene", "@x.gltf",   "--out",           "@out"};
  add_byte_variants(
      out, "gltf", [] { return gltf_base().dump(1); }, "x.gltf", gltf_context, args, "out",
      {0.001, 0.5, 0.99}, false);
  add_non_regular_variants(out, "gltf", "x.gltf", gltf_context, args, "out");
  std::vector<FieldMutation> m = {
      {"count_overflow", "/accessors/0/count", "4294967295", "count"},
      {"count_huge", "/accessors/0/count", "1000000000", "count"},
      {"count_past_view", "/accessors/1/count", "7", "count"},
      {"view_past_buffer", "/bufferViews/0/byteLength", "100000", "byteLength"},
      {"view_offset_huge", "/bufferViews/1/byteOffset", "18446744073709551615", "byteOffset"},
      {"stride_huge", "/bufferViews/0/byteStride", "252", "byteStride"},
      {"buffer_length_huge", "/buffers/0/byteLength", "100000000000", "byteLength"},
      {"uri_escape", "/buffers/0/uri", "\"../../../../../../etc/passwd\"", "uri"},
      {"uri_absolute", "/buffers/0/uri", "\"/dev/zero\"", "uri"},
      {"uri_missing", "/buffers/0/uri", "\"nowhere.bin\"", "uri"},
      {"uri_bad_base64", "/buffers/0/uri", "\"data:application/octet-stream;base64,@@@@\"", "uri"},
      {"node_cycle", "/nodes/1/children", "[0]", "children"},
      {"node_self_child", "/nodes/0/children", "[0]", "children"},
      {"child_out_of_range", "/nodes/0/children", "[99]", "children"},
      {"mesh_out_of_range", "/nodes/0/mesh", "7", "mesh"},
      {"accessor_out_of_range", "/meshes/0/primitives/0/indices", "9", "indices"},
      {"component_type_bogus", "/accessors/1/componentType", "1234", "componentType"},
      {"type_bogus", "/accessors/0/type", "\"VEC7\"", "type"},
      {"position_type_scalar", "/accessors/0/type", "\"SCALAR\"", "POSITION"},
      {"version_1", "/asset/version", "\"1.0\"", "version"},
      {"scene_out_of_range", "/scene", "5", "scene"},
      {"translation_nan", "/nodes/0/translation", "[NaN, 0, 0]", "translation"},
      {"matrix_short", "/nodes/0/matrix", "[1, 0, 0]", "matrix"},
  };
  add_json_variants(out, "gltf", gltf_base, "x.gltf", gltf_context, m, args, "out");
  out.push_back({"gltf_index_out_of_range",
                 [](const fs::path& dir) {
                   std::string bytes = gltf_buffer();
                   const std::uint16_t big = 60000;
                   std::memcpy(&bytes[48], &big, 2);
                   spit(dir / "square.bin", bytes);
                   spit(dir / "x.gltf", gltf_base().dump(1));
                 },
                 args,
                 "out",
                 {"x.gltf"}});
  out.push_back({"gltf_position_nan",
                 [](const fs::path& dir) {
                   std::string bytes = gltf_buffer();
                   const float nan = std::numeric_limits<float>::quiet_NaN();
                   std::memcpy(&bytes[0], &nan, 4);
                   spit(dir / "square.bin", bytes);
                   spit(dir / "x.gltf", gltf_base().dump(1));
                 },
                 args,
                 "out",
                 {"x.gltf"}});
  out.push_back({"gltf_buffer_truncated",
                 [](const fs::path& dir) {
                   spit(dir / "square.bin", gltf_buffer().substr(0, 30));
                   spit(dir / "x.gltf", gltf_base().dump(1));
                 },
                 args,
                 "out",
                 {"x.gltf", "square.bin"}});
}

// ---- Content for facet play: stills and videos --------------------------------------------------

// A valid still written with OpenImageIO: `width`×`height` RGB, a gradient.
std::string still_image(const std::string& extension, int width, int height) {
  const fs::path path =
      fs::temp_directory_path() / ("facet_hostile_still_" + std::to_string(::getpid()) + extension);
  std::vector<float> pixels(std::size_t(width) * height * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) {
    pixels[i] = float(i % 251) / 251.0f;
  }
  auto output = OIIO::ImageOutput::create(path.string());
  const bool is_float = extension == ".exr";
  output->open(
      path.string(),
      OIIO::ImageSpec(width, height, 3, is_float ? OIIO::TypeDesc::HALF : OIIO::TypeDesc::UINT8));
  output->write_image(OIIO::TypeDesc::FLOAT, pixels.data());
  output->close();
  std::string bytes = slurp(path);
  fs::remove(path);
  return bytes;
}

// A valid short video (MJPEG in AVI, 10 frames of 64×64) written with OpenCV's VideoWriter.
std::string short_video() {
  static const std::string bytes = [] {
    const fs::path path =
        fs::temp_directory_path() / ("facet_hostile_video_" + std::to_string(::getpid()) + ".avi");
    cv::VideoWriter writer(path.string(), cv::CAP_FFMPEG,
                           cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), 30, cv::Size(64, 64));
    for (int k = 0; k < 10; ++k)
      writer.write(cv::Mat(64, 64, CV_8UC3, cv::Scalar(20 * k, 90, 200)));
    writer.release();
    std::string video = slurp(path);
    fs::remove(path);
    return video;
  }();
  return bytes;
}

std::uint32_t crc32_of(const std::string& bytes) {
  std::uint32_t crc = 0xffffffffu;
  for (const char c : bytes) {
    crc ^= static_cast<unsigned char>(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

void put_be32(std::string& bytes, std::size_t offset, std::uint32_t value) {
  for (int k = 0; k < 4; ++k) bytes[offset + k] = static_cast<char>(value >> (24 - 8 * k));
}

// A valid PNG whose IHDR (with a correct CRC) claims `width`×`height`.
std::string png_claiming(std::uint32_t width, std::uint32_t height) {
  std::string png = still_image(".png", 16, 16);
  put_be32(png, 16, width);  // signature 8, length 4, "IHDR" 4
  put_be32(png, 20, height);
  put_be32(png, 29, crc32_of(png.substr(12, 17)));
  return png;
}

// A valid JPEG whose first SOF marker claims `width`×`height`.
std::string jpeg_claiming(std::uint16_t width, std::uint16_t height) {
  std::string jpeg = still_image(".jpg", 16, 16);
  for (std::size_t i = 2; i + 9 < jpeg.size(); ++i) {
    if (static_cast<unsigned char>(jpeg[i]) == 0xff &&
        (static_cast<unsigned char>(jpeg[i + 1]) & 0xf0) == 0xc0 &&
        static_cast<unsigned char>(jpeg[i + 1]) != 0xc4) {
      jpeg[i + 5] = static_cast<char>(height >> 8);
      jpeg[i + 6] = static_cast<char>(height & 0xff);
      jpeg[i + 7] = static_cast<char>(width >> 8);
      jpeg[i + 8] = static_cast<char>(width & 0xff);
      break;
    }
  }
  return jpeg;
}

std::vector<std::string> play_args(const std::string& file, std::vector<std::string> extra = {}) {
  std::vector<std::string> args{"play",   "@" + file, "--display",  "builtin:dome180",
                                "--size", "32x32",    "--headless", "--frames",
                                "1",      "--out",    "@out"};
  args.insert(args.end(), extra.begin(), extra.end());
  return args;
}

void add_play_content(std::vector<Variant>& out) {
  add_byte_variants(out, "play_png", [] { return still_image(".png", 64, 64); }, "x.png", nullptr,
                    play_args("x.png"), "out", {0.01, 0.5, 0.95});
  add_byte_variants(out, "play_video", short_video, "x.avi", nullptr, play_args("x.avi"), "out",
                    {0.01, 0.3, 0.6});
  add_non_regular_variants(out, "play_video", "x.mp4", nullptr, play_args("x.mp4"), "out");
  auto add = [&](const std::string& what, const std::string& file,
                 std::function<std::string()> bytes, std::vector<std::string> extra = {}) {
    out.push_back({"play_" + what,
                   [file, bytes](const fs::path& dir) { spit(dir / file, bytes()); },
                   play_args(file, std::move(extra)),
                   "out",
                   {file}});
  };
  add("png_claims_100000x100000", "x.png", [] { return png_claiming(100000, 100000); });
  add("png_claims_2e9_wide", "x.png", [] { return png_claiming(2000000000, 1); });
  add("jpeg_truncated", "x.jpg", [] { return truncated(still_image(".jpg", 64, 64), 300); });
  add("jpeg_claims_65000x65000", "x.jpg", [] { return jpeg_claiming(65000, 65000); });
  add("exr_truncated", "x.exr", [] {
    const std::string exr = still_image(".exr", 64, 64);
    return truncated(exr, exr.size() / 2);
  });
  add("exr_header_only", "x.exr", [] { return truncated(still_image(".exr", 64, 64), 200); });
  add("exr_magic_flipped", "x.exr", [] { return flipped(still_image(".exr", 64, 64), 0); });
  add("fisheye_not_square", "x.png", [] { return still_image(".png", 64, 32); },
      {"--format", "fisheye"});
  add("equirect_square", "x.png", [] { return still_image(".png", 64, 64); },
      {"--format", "equirect"});
  add("cubemap_square", "x.png", [] { return still_image(".png", 64, 64); },
      {"--format", "cubemap"});
  add("aspect_unknown", "x.png", [] { return still_image(".png", 64, 48); });
  add("text_as_video", "x.mp4", [] { return std::string("this is not a video\n"); });
  add("video_header_only", "x.avi", [] { return truncated(short_video(), 64); });
  add("video_zero_bytes_after_header", "x.avi", [] {
    std::string v = short_video();
    std::fill(v.begin() + 512, v.end(), '\0');
    return v;
  });
  add("video_named_png", "x.png", short_video);
}

// ---- Materials: a user's GLSL FILE.frag ---------------------------------------------------------

std::string material_base() { return slurp(kSource / "shaders/scene/materials/procedural.frag"); }

void add_material(std::vector<Variant>& out) {
  const std::vector<std::string> args{"render",  "--display", "builtin:dome180",
                                      "--size",  "32x32",     "--material",
                                      "@m.frag", "--out",     "@out"};
  add_byte_variants(out, "material", material_base, "m.frag", nullptr, args, "out", {0.3, 0.97},
                    false);
  add_non_regular_variants(out, "material", "m.frag", nullptr, args, "out");
  auto add = [&](const std::string& what, std::function<std::string()> text,
                 std::vector<std::string> command = {}) {
    out.push_back({"material_" + what,
                   [text](const fs::path& dir) { spit(dir / "m.frag", text()); },
                   command.empty() ? args : command,
                   "out",
                   {"m.frag"}});
  };
  add("syntax_error", [] { return replace_first(material_base(), "vec4 shade(", "vec4 shade(("); });
  add("undefined_name", [] { return material_base() + "\nfloat f() { return nowhere; }\n"; });
  add("discard", [] {
    return replace_first(material_base(), "vec4 shade(MaterialInput m) {",
                         "vec4 shade(MaterialInput m) {\n  if (m.depth > 2.0) discard;");
  });
  add("frag_depth", [] {
    return replace_first(material_base(), "vec4 shade(MaterialInput m) {",
                         "vec4 shade(MaterialInput m) {\n  gl_FragDepth = 0.5;");
  });
  add("no_shade", [] { return replace_all(material_base(), "shade(", "shade_not("); });
  add("shade_returns_vec3", [] { return "vec3 shade(MaterialInput m) { return vec3(1); }\n"; });
  add("shade_wrong_parameter", [] { return "vec4 shade(vec3 m) { return vec4(1); }\n"; });
  add("shade_twice",
      [] { return material_base() + "\nvec4 shade(MaterialInput m) { return vec4(1); }\n"; });
  add("defines_main", [] { return material_base() + "\nvoid main() {}\n"; });
  add("redefines_sun_and_sky",
      [] { return material_base() + "\nvec3 sun_and_sky(MaterialInput m) { return vec3(0); }\n"; });
  add("version_directive", [] { return "#version 110\n" + material_base(); });
  add("include_directive", [] { return "#include \"/etc/passwd\"\n" + material_base(); });
  add("recursion", [] {
    return "float r(float x) { return x > 0.0 ? r(x - 1.0) : 0.0; }\n"
           "vec4 shade(MaterialInput m) { return vec4(r(3.0)); }\n";
  });
  add("invalid_utf8", [] { return replace_first(material_base(), "marble", "\xff\xfe\xfd"); });
  add("nul_bytes", [] { return material_base() + std::string(64, '\0'); });
  add("huge_40MiB", [] { return material_base() + "//" + std::string(40u << 20, 'x') + "\n"; });
  add("huge_one_line",
      [] { return "float f = " + std::string(2u << 20, '1') + ".0;\n" + material_base(); });
  add("run_syntax_error",
      [] { return replace_first(material_base(), "vec4 shade(", "vec4 shade(("); },
      {"run", (kSource / "configs/displays/dome180/display.json").string(), "--headless",
       "--frames", "1", "--scale", "0.125", "--material", "@m.frag", "--out", "@out"});
  add("run_discard",
      [] {
        return replace_first(material_base(), "vec4 shade(MaterialInput m) {",
                             "vec4 shade(MaterialInput m) {\n  discard;");
      },
      {"run", (kSource / "configs/displays/dome180/display.json").string(), "--headless",
       "--frames", "1", "--scale", "0.125", "--material", "@m.frag", "--out", "@out"});
}

// ---- Clusters: display.json's cluster section and facet run --node ------------------------------

// cylinder3 spread over three nodes listening on ipc:// addresses in the scratch folder.
json cluster_base(const fs::path& dir) {
  json display = display_base();
  auto node = [&](const std::string& name, json projectors) {
    return json{{"name", name},
                {"address", "ipc://" + (dir / ("n-" + name)).string()},
                {"projectors", std::move(projectors)}};
  };
  display["cluster"] = {
      {"nodes", {node("left", {"p0"}), node("mid", {"p1"}), node("right", {"p2"})}},
      {"master", "left"},
      {"deadline_ms", 50}};
  return display;
}

void add_cluster_section(std::vector<Variant>& out) {
  // A secondary: it listens on its address, then waits for the master (which never comes).
  const std::vector<std::string> args{"run", "@display.json", "--node",
                                      "mid", "--headless",    "--join-timeout",
                                      "2",   "--out",         "@out"};
  const std::vector<FieldMutation> m = {
      {"cluster_array", "/cluster", "[]", "cluster"},
      {"nodes_empty", "/cluster/nodes", "[]", "nodes"},
      {"nodes_object", "/cluster/nodes", "{}", "nodes"},
      {"node_name_missing", "/cluster/nodes/1/name", "", "name"},
      {"node_name_duplicate", "/cluster/nodes/2/name", "\"mid\"", "mid"},
      {"node_name_invalid_utf8", "/cluster/nodes/2/name", "\"r\xff\xfe\"", "name"},
      {"node_name_slash", "/cluster/nodes/2/name", "\"../x\"", "name"},
      {"address_http", "/cluster/nodes/1/address", "\"http://localhost:80\"", "address"},
      {"address_empty", "/cluster/nodes/1/address", "\"\"", "address"},
      {"address_number", "/cluster/nodes/1/address", "7400", "address"},
      {"address_port_huge", "/cluster/nodes/1/address", "\"tcp://127.0.0.1:99999\"", "address"},
      {"address_port_last", "/cluster/nodes/1/address", "\"tcp://127.0.0.1:65535\"", "address"},
      {"address_host_bogus", "/cluster/nodes/1/address", "\"tcp://no host:7400\"", "address"},
      {"address_ipc_too_long", "/cluster/nodes/1/address",
       "\"ipc:///tmp/" + std::string(200, 'a') + "\"", "address"},
      {"address_ipc_missing_folder", "/cluster/nodes/1/address", "\"ipc:///nowhere/at/all/n\"",
       "address"},
      {"address_duplicate", "/cluster/nodes/1/address", "\"@ADDR0@\"", "address"},
      {"projector_unknown", "/cluster/nodes/1/projectors", "[\"p9\"]", "p9"},
      {"projector_on_two_nodes", "/cluster/nodes/1/projectors", "[\"p1\", \"p0\"]", "p0"},
      {"projector_on_no_node", "/cluster/nodes/2/projectors", "[\"p1\"]", "p2"},
      {"projectors_empty", "/cluster/nodes/1/projectors", "[]", "projectors"},
      {"critical_string", "/cluster/nodes/1/critical", "\"yes\"", "critical"},
      {"master_unknown", "/cluster/master", "\"nobody\"", "nobody"},
      {"master_missing", "/cluster/master", "", "master"},
      {"deadline_zero", "/cluster/deadline_ms", "0", "deadline_ms"},
      {"deadline_negative", "/cluster/deadline_ms", "-50", "deadline_ms"},
      {"deadline_huge", "/cluster/deadline_ms", "1e300", "deadline_ms"},
      {"deadline_nan", "/cluster/deadline_ms", "NaN", "deadline_ms"},
      {"deadline_string", "/cluster/deadline_ms", "\"50\"", "deadline_ms"},
      {"unknown_key", "/cluster/surprise", "1", "surprise"},
  };
  for (const FieldMutation& f : m) {
    out.push_back({"cluster_" + sanitize(f.what),
                   [f](const fs::path& dir) {
                     display_context(dir);
                     const json base = cluster_base(dir);
                     std::string raw = f.raw;
                     if (raw == "\"@ADDR0@\"") raw = base["cluster"]["nodes"][0]["address"].dump();
                     spit(dir / "display.json", json_with(base, f.pointer, raw));
                   },
                   args,
                   "out",
                   {"display.json", f.mention}});
  }
  auto add_flag = [&](const std::string& what, std::vector<std::string> command,
                      const std::string& mention, bool with_cluster = true) {
    out.push_back({"cluster_flag_" + what,
                   [with_cluster](const fs::path& dir) {
                     display_context(dir);
                     spit(dir / "display.json",
                          (with_cluster ? cluster_base(dir) : display_base()).dump(1));
                   },
                   std::move(command),
                   "out",
                   {mention}});
  };
  auto run = [](std::vector<std::string> flags) {
    std::vector<std::string> command{"run", "@display.json", "--headless", "--frames",
                                     "1",   "--out",         "@out"};
    command.insert(command.end(), flags.begin(), flags.end());
    return command;
  };
  add_flag("node_unknown", run({"--node", "nobody"}), "nobody");
  add_flag("node_empty", run({"--node", ""}), "--node");
  add_flag("node_invalid_utf8", run({"--node", "m\xff\xfe"}), "--node");
  add_flag("node_without_cluster", run({"--node", "mid"}), "cluster", false);
  add_flag("join_timeout_negative", run({"--node", "left", "--join-timeout", "-1"}),
           "--join-timeout");
  add_flag("join_timeout_nan", run({"--node", "left", "--join-timeout", "nan"}), "--join-timeout");
  add_flag("join_timeout_huge", run({"--node", "left", "--join-timeout", "1e300"}),
           "--join-timeout");
  add_flag("rate_zero", run({"--node", "left", "--rate", "0"}), "--rate");
  add_flag("rate_nan", run({"--node", "left", "--rate", "nan"}), "--rate");
  out.push_back({"cluster_flag_play_node_unknown",
                 [](const fs::path& dir) {
                   display_context(dir);
                   spit(dir / "display.json", cluster_base(dir).dump(1));
                   spit(dir / "x.png", still_image(".png", 64, 64));
                 },
                 {"play", "@x.png", "--display", "@display.json", "--headless", "--frames", "1",
                  "--node", "nobody", "--out", "@out"},
                 "out",
                 {"nobody"}});
}

// Flags: bad values of the CLI's own options, each command with a valid input.
// ---- Depth images (--scene depth:FILE.exr) --------------------------------------------------

// A valid planar depth image, 8 × 6, every pixel 5 m away facing the eye.
Exr depth_exr_base() {
  Exr exr;
  exr.width = 8;
  exr.height = 6;
  exr.channels = {"R", "G", "B", "Z", "N.x", "N.y", "N.z"};
  for (int k = 0; k < 48; ++k)
    exr.pixels.insert(exr.pixels.end(), {0.5f, 0.5f, 0.5f, 5.0f, 0.0f, 0.0f, 1.0f});
  const json meta = {{"format", "facet-depth-image/1"},
                     {"kind", "planar"},
                     {"part", "planar"},
                     {"base", "perspective"},
                     {"tan_extent", {-1.0, 1.0, 0.75, -0.75}},
                     {"rotation", {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}},
                     {"T_world_image", {{1, 0, 0, 0}, {0, 1, 0, 1.7}, {0, 0, 1, 0}, {0, 0, 0, 1}}}};
  exr.attributes = {{"facet:depth_image", meta.dump()}};
  return exr;
}

std::string depth_exr_bytes() {
  const fs::path file =
      fs::temp_directory_path() / ("facet_hostile_depth_" + std::to_string(::getpid()) + ".exr");
  write_exr(file, depth_exr_base());
  std::string bytes = slurp(file);
  std::error_code ec;
  fs::remove(file, ec);
  return bytes;
}

void add_depth_image(std::vector<Variant>& out) {
  const std::vector<std::string> render{"render",      "--display", "builtin:dome180",
                                        "--size",      "16x16",     "--scene",
                                        "depth:x.exr", "--out",     "@out"};
  add_byte_variants(out, "depth_exr", depth_exr_bytes, "x.exr", nullptr, render, "out");
  add_non_regular_variants(out, "depth_exr", "x.exr", nullptr, render, "out");
  for (const auto& [what, x_max, y_max] :
       {std::tuple{"huge", 1 << 30, 1 << 30}, std::tuple{"inverted", -5, -5}}) {
    const std::int32_t x = x_max, y = y_max;
    out.push_back({std::string("depth_exr_data_window_") + what,
                   [x, y](const fs::path& dir) {
                     spit(dir / "x.exr", exr_with_data_window(depth_exr_bytes(), x, y));
                   },
                   render,
                   "out",
                   {"x.exr"}});
  }
  auto add_exr = [&](const std::string& what, std::function<void(Exr&)> mutate,
                     const std::string& mention) {
    out.push_back({"depth_exr_" + what,
                   [mutate](const fs::path& dir) {
                     Exr exr = depth_exr_base();
                     mutate(exr);
                     write_exr(dir / "x.exr", exr);
                   },
                   render,
                   "out",
                   {"x.exr", mention}});
  };
  // Channel c of pixel k set to v.
  auto set = [](int k, int c, float v) {
    return [k, c, v](Exr& exr) { exr.pixels[std::size_t(k * 7 + c)] = v; };
  };
  auto without = [](const std::string& channel) {
    return [channel](Exr& exr) {
      for (std::size_t c = 0; c < exr.channels.size(); ++c) {
        if (exr.channels[c] == channel) exr.channels[c] = "unused";
      }
    };
  };
  auto with_meta = [](const std::string& pointer, const std::string& raw) {
    return [pointer, raw](Exr& exr) {
      for (auto& [key, value] : exr.attributes) value = json_with(json::parse(value), pointer, raw);
    };
  };
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  add_exr("no_normal_x", without("N.x"), "N.x");
  add_exr("no_depth", without("Z"), "Z");
  add_exr("no_green", without("G"), "G");
  add_exr("depth_nan", set(9, 3, nan), "Z");
  add_exr("depth_minus_inf", set(9, 3, -inf), "Z");
  add_exr("depth_zero", set(9, 3, 0.0f), "Z");
  add_exr("depth_negative", set(9, 3, -2.0f), "Z");
  add_exr("normal_zero", set(9, 6, 0.0f), "N.x");
  add_exr("normal_nan", set(9, 4, nan), "N.x");
  add_exr("normal_long", set(9, 6, 1.5f), "N.x");
  add_exr("colour_inf", set(9, 0, inf), "R,G,B");
  add_exr(
      "meta_missing", [](Exr& exr) { exr.attributes.clear(); }, "facet:depth_image");
  add_exr(
      "meta_not_json",
      [](Exr& exr) {
        exr.attributes = {{"facet:depth_image", "{"}};
      },
      "facet:depth_image");
  add_exr("meta_format_unknown", with_meta("/format", "\"facet-depth-image/9\""), "format");
  add_exr("meta_kind_bogus", with_meta("/kind", "\"sphere\""), "kind");
  add_exr("meta_kind_dpci_one_part", with_meta("/kind", "\"dpci\""), "parts");
  add_exr("meta_part_renamed", with_meta("/part", "\"cap\""), "parts");
  add_exr("meta_base_fisheye", with_meta("/base", "\"fisheye\""), "base");
  add_exr("meta_tan_extent_short", with_meta("/tan_extent", "[1, 2]"), "tan_extent");
  add_exr("meta_tan_extent_flat", with_meta("/tan_extent", "[1, 1, 1, 1]"), "tan_extent");
  add_exr("meta_rotation_scaled", with_meta("/rotation", "[[2,0,0],[0,2,0],[0,0,2]]"), "rotation");
  add_exr("meta_pose_scaled",
          with_meta("/T_world_image", "[[3,0,0,0],[0,3,0,0],[0,0,3,0],[0,0,0,1]]"),
          "T_world_image");
  add_exr("meta_pose_not_numbers", with_meta("/T_world_image", "\"identity\""), "T_world_image");
}

void add_flags(std::vector<Variant>& out) {
  const std::string dome = (kSource / "configs/displays/dome180/display.json").string();
  const std::string warp = (kSource / "configs/displays/dome180/dome180.warp.exr").string();
  auto add = [&](const std::string& what, std::vector<std::string> args,
                 const std::string& mention) {
    out.push_back({"flag_" + what, nullptr, std::move(args), "out", {mention}});
  };
  add("render_size_negative",
      {"render", "--display", "builtin:dome180", "--size", "-5x5", "--out", "@out"}, "--size");
  add("render_size_huge",
      {"render", "--display", "builtin:dome180", "--size", "100000x100000", "--out", "@out"},
      "--size");
  // Within --preview-size's range, but its maps need about 2.1 GiB: refused up front (it ended in
  // std::bad_alloc).
  add("preview_size_over_memory", {"preview", dome, "--preview-size", "6000", "--out", "@out"},
      "--preview-size");
  address_limited().insert("flag_preview_size_over_memory");
  add("render_size_text",
      {"render", "--display", "builtin:dome180", "--size", "big", "--out", "@out"}, "--size");
  add("render_frames_zero",
      {"render", "--display", "builtin:dome180", "--frames", "0", "--out", "@out"}, "--frames");
  add("render_msaa_huge",
      {"render", "--display", "builtin:dome180", "--size", "32x32", "--msaa", "4096", "--out",
       "@out"},
      "--msaa");
  add("render_grid_zero",
      {"render", "--display", "builtin:dome180", "--grid", "0x0", "--out", "@out"}, "--grid");
  add("render_tolerance_nan",
      {"render", "--display", "builtin:dome180", "--tolerance", "nan", "--out", "@out"},
      "--tolerance");
  add("render_eye_nan",
      {"render", "--display", "builtin:dome180", "--eye", "nan,0,0", "--out", "@out"}, "--eye");
  add("render_method_bogus",
      {"render", "--display", "builtin:dome180", "--method", "bogus", "--out", "@out"}, "--method");
  add("render_scene_builtin_huge",
      {"render", "--display", "builtin:dome180", "--scene", "builtin:city:100000000", "--out",
       "@out"},
      "scene");
  add("render_display_builtin_bogus", {"render", "--display", "builtin:bogus", "--out", "@out"},
      "builtin:bogus");
  add("run_scale_zero", {"run", dome, "--headless", "--scale", "0", "--out", "@out"}, "--scale");
  add("run_frames_negative", {"run", dome, "--headless", "--frames", "-1", "--out", "@out"},
      "--frames");
  add("lookup_out_in_missing_dir", {"lookup", "--warp", warp, "--out", "@out/deeper/x.exr"}, "out");
  add("display_size_huge",
      {"display", "builtin:dome180", "--size", "2000000000x2000000000", "--out", "@out"}, "--size");
  add("simulate_camera_size_huge",
      {"simulate", "--rig", "builtin:wall2x2", "--camera-size", "2000000000x2000000000", "--out",
       "@out"},
      "--camera-size");
  add("simulate_noise_nan",
      {"simulate", "--rig", "builtin:wall2x2", "--noise", "nan", "--out", "@out"}, "--noise");
  add("simulate_bits_9", {"simulate", "--rig", "builtin:wall2x2", "--bits", "9", "--out", "@out"},
      "--bits");
  add("simulate_gamma_negative",
      {"simulate", "--rig", "builtin:wall2x2", "--gamma", "-1", "--out", "@out"}, "--gamma");
  add("calibrate_grid_huge",
      {"calibrate", kCapture.string(), "--grid", "100000x100000", "--out", "@out"}, "--grid");
  add("calibrate_node_spacing_zero",
      {"calibrate", kCapture.string(), "--node-spacing", "0", "--out", "@out"}, "--node-spacing");
  add("mpcdi_grid_huge",
      {"mpcdi", "import", kMpcdi.string(), "--grid", "100000x100000", "--out", "@out"}, "--grid");
  add("mpcdi_tilt_out_of_range",
      {"mpcdi", "import", kMpcdi.string(), "--tilt", "91", "--out", "@out"}, "--tilt");
  add("mpcdi_warp_values_bogus",
      {"mpcdi", "import", kMpcdi.string(), "--warp-values", "bogus", "--out", "@out"},
      "--warp-values");
  add("mpcdi_eye_nan", {"mpcdi", "import", kMpcdi.string(), "--eye", "nan,0,0", "--out", "@out"},
      "--eye");
  add("bourke_size_aspect",
      {"bourke", "import", kBourke.string(), "--size", "1000x1000", "--out", "@out"}, "--size");
  add("bourke_fov_zero", {"bourke", "import", kBourke.string(), "--fov", "0", "--out", "@out"},
      "--fov");
  add("bourke_gamma_nan",
      {"bourke", "import", kBourke.string(), "--intensity-gamma", "nan", "--out", "@out"},
      "--intensity-gamma");
  add("bourke_zenith_bogus",
      {"bourke", "import", kBourke.string(), "--zenith", "up", "--out", "@out"}, "--zenith");
  add("sgct_size_zero", {"sgct", "import", kSgc.string(), "--size", "0x0", "--out", "@out"},
      "--size");
  add("sgct_grid_one", {"sgct", "import", kSgc.string(), "--grid", "1x1", "--out", "@out"},
      "--grid");
  add("sgct_orientation_inf",
      {"sgct", "import", kSgc.string(), "--orientation", "inf", "--out", "@out"}, "--orientation");
}

// ---- Every value-taking flag of every command: at least 20 bad values each ----------------------
//
// Each flag gets bad values by the type of value it takes (a count, a real, an angle, WxH, a
// point, a name from a list, a name, an input file, an output), on a command line that is valid
// without it.

// The flag each variant exercises, by name; and those with the scratch fixtures below (whose
// foreign files must survive the run).
std::map<std::string, std::string>& flag_of() {
  static std::map<std::string, std::string> flags;
  return flags;
}
std::set<std::string>& with_fixtures() {
  static std::set<std::string> names;
  return names;
}

const std::string kLongName(300, 'n');  // longer than a file name may be (255)

// Things a path may name that are not what a command wants, in the scratch folder.
void make_fixtures(const fs::path& dir) {
  fs::create_directories(dir / "dir");
  fs::create_directories(dir / "foreign");
  spit(dir / "foreign/keep", "the user's");
  spit(dir / "file", "the user's");
  spit(dir / "empty", "");
  std::string garbage(4096, '\0');
  for (std::size_t i = 0; i < garbage.size(); ++i) {
    garbage[i] = static_cast<char>((i * 2654435761u) >> 13);
  }
  spit(dir / "garbage", garbage);
  spit(dir / "nul", std::string("{\"a\0\": 1}", 10));
  spit(dir / "invalid_utf8", "{\"\xff\xfe\": \"\xc0\x80\"}");
  spit(dir / "deep", std::string(100000, '[') + std::string(100000, ']'));
  spit(dir / "array", "[1, 2, 3]");
  ::mkfifo((dir / "fifo").c_str(), 0644);
  ::mknod((dir / "null_dev").c_str(), S_IFCHR | 0666, ::makedev(1, 3));  // a copy of /dev/null
  fs::create_symlink("/dev/zero", dir / "zero_link");
  fs::create_symlink("/dev/null", dir / "null_link");
  fs::create_symlink("/dev/full", dir / "full_link");
  fs::create_symlink(dir / "gone", dir / "dangling");
  fs::create_symlink(dir / "loop", dir / "loop");
  fs::create_symlink(dir / "foreign", dir / "foreign_link");
  fs::create_symlink(dir / "file", dir / "file_link");
}

// The fixtures' foreign files are untouched.
bool fixtures_intact(const fs::path& dir) {
  return slurp(dir / "file") == "the user's" && slurp(dir / "foreign/keep") == "the user's" &&
         fs::is_directory(dir / "dir") && fs::is_fifo(dir / "fifo") &&
         fs::is_symlink(dir / "null_link") && fs::is_symlink(dir / "full_link") &&
         fs::is_character_file(dir / "null_dev");
}

std::vector<std::string> operator+(std::vector<std::string> a, const std::vector<std::string>& b) {
  a.insert(a.end(), b.begin(), b.end());
  return a;
}

// Text that is no number at all.
const std::vector<std::string> kNotNumbers = {
    "", " ", "abc", "5abc", "1 2", "\xff\xfe", "7\xed\xa0\x80", "1,2", "1..2", "+-1", "e5", "."};
const std::vector<std::string> kNonFinite = {"nan",  "NaN",      "-nan", "inf",
                                             "-inf", "infinity", "1e400"};

// A count from 1 up (`over`: values past its largest).
std::vector<std::string> counts(std::vector<std::string> over = {}) {
  return kNotNumbers +
         std::vector<std::string>{
             "nan", "inf",   "-inf",       "-1",          "0",
             "1.5", "1e308", "2147483648", "-2147483649", "99999999999999999999"} +
         over;
}
// A count from 0 up.
std::vector<std::string> naturals(std::vector<std::string> over = {}) {
  return kNotNumbers + std::vector<std::string>{"nan",   "inf",         "-inf",
                                                "-1",    "-2147483648", "1.5",
                                                "1e308", "2147483648",  "99999999999999999999"} +
         over;
}
// Any unsigned integer.
std::vector<std::string> unsigneds() {
  return kNotNumbers + std::vector<std::string>{"nan",
                                                "inf",
                                                "-inf",
                                                "-1",
                                                "1.5",
                                                "1e308",
                                                "18446744073709551616",
                                                "99999999999999999999"};
}
// A positive real (`over`: values past its largest).
std::vector<std::string> positives(std::vector<std::string> over = {}) {
  return kNotNumbers + kNonFinite + std::vector<std::string>{"-1", "0", "1e308", "-1e308"} + over;
}
// A real from 0 up.
std::vector<std::string> non_negatives(std::vector<std::string> over = {}) {
  return kNotNumbers + kNonFinite + std::vector<std::string>{"-1", "-1e-9", "1e308", "-1e308"} +
         over;
}
// An angle in [-limit, limit] degrees.
std::vector<std::string> angles(const std::string& past) {
  return kNotNumbers + kNonFinite +
         std::vector<std::string>{"1e308", "-1e308", past, "-" + past, past + "deg"};
}
// WxH in pixels (`over`: sizes past the largest).
std::vector<std::string> sizes(std::vector<std::string> over = {}) {
  return std::vector<std::string>{"",
                                  "x",
                                  "5",
                                  "5x",
                                  "x5",
                                  "0x0",
                                  "0x5",
                                  "5x0",
                                  "-5x5",
                                  "5x-5",
                                  "1.5x2",
                                  "axb",
                                  "5x5x5",
                                  "5x5abc",
                                  "5x5\xff",
                                  "5*5",
                                  "5,5",
                                  "nanxnan",
                                  "infx5",
                                  "\xff\xfe",
                                  "100000x100000",
                                  "2000000000x2000000000",
                                  "99999999999x1",
                                  "1x99999999999"} +
         over;
}
// A point X,Y,Z.
std::vector<std::string> points() {
  return {"",        "1",        "1,2",       "1,2,3,4",    "nan,0,0",   "0,nan,0", "0,0,nan",
          "inf,0,0", "0,-inf,0", "1e308,0,0", "0,0,-1e308", "1e400,0,0", "a,b,c",   "1,2,3abc",
          ",,",      "1;2;3",    "\xff,0,0",  "1,,2",       " ",         "0,0,1e39"};
}
// Two reals A,B (`more`: values bad for this flag's meaning).
std::vector<std::string> pairs(std::vector<std::string> more = {}) {
  return std::vector<std::string>{"",      "1",      "1,2,3",   "nan,1",    "1,nan",
                                  "inf,1", "1,-inf", "1e308,1", "1,-1e308", "1e400,0",
                                  "a,b",   "1,2abc", ",",       "1;2",      "\xff,1",
                                  " ",     "1,,2",   "nan,nan", "1,2,",     "+-1,2"} +
         more;
}
// One of a list of names, `valid` being one of them.
std::vector<std::string> choices(const std::string& valid) {
  std::string upper = valid;
  for (char& c : upper) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return {"",
          " ",
          "bogus",
          upper,
          valid + " ",
          " " + valid,
          valid + "," + valid,
          valid + "-",
          valid + "\xff",
          "\xff\xfe",
          "nan",
          "inf",
          "0",
          "-1",
          "1e308",
          "5abc",
          "../" + valid,
          valid + "\n",
          valid.substr(0, valid.size() - 1),
          "x" + valid,
          valid + valid};
}
// A name (of a display, a node, a camera): blank, not UTF-8, holding control characters or too
// long.
std::vector<std::string> names() {
  return {"",
          " ",
          "\t",
          "  \t ",
          "\xff\xfe",
          "a\xc0\xaf",
          "a\xed\xa0\x80",
          "a\xe2\x82",
          "\xf8\x88\x80\x80\x80",
          "\xf4\x90\x80\x80",
          "\xc3",
          "\x80"
          "qrs",
          "a\nb",
          "a\tb",
          "a\x01",
          "a\x7f",
          "a\rb",
          "a\x1b[31m",
          std::string(257, 'n'),
          std::string(100000, 'n')};
}
// An input file of a kind named by `extension`.
std::vector<std::string> inputs(const std::string& extension) {
  return {"",
          "{dir}/missing" + extension,
          "{dir}/dir",
          "{dir}/fifo",
          "/dev/zero",
          "/dev/null",
          "{dir}/zero_link",
          "{dir}/null_dev",
          "{dir}/dangling",
          "{dir}/empty",
          "{dir}/garbage",
          "{dir}/nul",
          "{dir}/invalid_utf8",
          "{dir}/" + kLongName + extension,
          "{dir}/file/x" + extension,
          "{dir}/loop",
          "\xff\xfe" + extension,
          "{dir}/deep",
          "{dir}/array",
          "{dir}/foreign"};
}
// An output folder.
std::vector<std::string> out_folders() {
  return {"",
          ".",
          "{dir}",
          "{dir}/",
          "{dir}/fifo",
          "{dir}/file",
          "{dir}/file_link",
          "{dir}/foreign",
          "{dir}/foreign/",
          "{dir}/foreign_link",
          "{dir}/file/x",
          "{dir}/" + kLongName,
          "{dir}/loop",
          "{dir}/loop/x",
          "{dir}/zero_link",
          "{dir}/null_link",
          "{dir}/null_dev",
          "{dir}/dangling",
          "/proc/facet_hostile_out",
          "/sys/facet_hostile_out"};
}
// An output file with `extension`.
std::vector<std::string> out_files(const std::string& extension) {
  return {"",
          ".",
          "{dir}",
          "{dir}/",
          "{dir}/fifo",
          "{dir}/dir",
          "{dir}/foreign/",
          "{dir}/foreign_link",
          "{dir}/file/x" + extension,
          "{dir}/" + kLongName + extension,
          "{dir}/loop",
          "{dir}/loop/x" + extension,
          "{dir}/zero_link",
          "{dir}/null_link",
          "{dir}/null_dev",
          "{dir}/dangling",
          "{dir}/missing/x" + extension,
          "/proc/facet_hostile_out" + extension,
          "/sys/facet_hostile_out" + extension,
          "{dir}/full_link"};
}
// A scene name.
std::vector<std::string> scenes() {
  return {"",
          "builtin:",
          "builtin:bogus",
          "builtin:city:0",
          "builtin:city:-1",
          "builtin:city:100000000",
          "builtin:city:nan",
          "builtin:city:1e308",
          "builtin:city:5abc",
          "builtin:city-fine:0",
          "builtin:city-fine:100000",
          "{dir}/missing.gltf",
          "{dir}/dir",
          "{dir}/fifo",
          "/dev/zero",
          "{dir}/garbage",
          "depth:",
          "depth:{dir}/missing.exr",
          "depth:/dev/zero",
          "builtin:city+depth:",
          "\xff\xfe",
          "{dir}/loop"};
}

// One command line that is valid as it stands; `output` is what it would write (relative to the
// scratch folder); `make` writes its inputs there.
struct Base {
  std::vector<std::string> args;
  std::string output;
  std::function<void(const fs::path&)> make;
};

// The variants of `flag` on `base`, one per value, as --flag=VALUE (so that values starting with
// '-' stay values).
void add_flag_values(std::vector<Variant>& out, const std::string& command, const Base& base,
                     const std::string& flag, const std::vector<std::string>& values,
                     std::vector<std::string> before = {}) {
  const std::string label = command + " " + flag;
  std::size_t i = 0;
  for (const std::string& value : values) {
    const std::string name = "flag_" + sanitize(command) + "_" + sanitize(flag.substr(2)) + "_" +
                             std::to_string(i++) + "_" + sanitize(value.substr(0, 24));
    // The base without the flag itself (given twice, CLI11 would refuse it for that alone).
    std::vector<std::string> args;
    for (std::size_t k = 0; k < base.args.size(); ++k) {
      if (base.args[k] == flag) {
        ++k;
        continue;
      }
      args.push_back(base.args[k]);
    }
    args.insert(args.end(), before.begin(), before.end());
    args.push_back(flag + "=" + value);
    const auto make = base.make;
    // A file's or folder's error may name it rather than the flag.
    const fs::path as_path(value);
    const std::string extension = as_path.extension().string();
    const bool path_like =
        value.find('/') != std::string::npos ||
        (extension.size() > 1 && std::isalpha(static_cast<unsigned char>(extension[1])));
    std::vector<std::string> mentions{flag};
    if (path_like) mentions.push_back(value);
    // A path after a scheme (depth:FILE, fake:RIG) may be named alone.
    if (const auto colon = value.find(':');
        path_like && colon != std::string::npos && colon < value.find('/')) {
      mentions.push_back(value.substr(colon + 1));
    }
    out.push_back({name,
                   [make](const fs::path& dir) {
                     make_fixtures(dir);
                     if (make) make(dir);
                   },
                   std::move(args), base.output, std::move(mentions), false});
    flag_of()[name] = label;
    with_fixtures().insert(name);
  }
}

// The bases, and the flags of each command.
Base render_base() {
  return {
      {"render", "--display", "builtin:dome180", "--size", "64x64", "--out", "@out"}, "out", {}};
}
Base run_base() {
  return {
      {"run", "builtin:dome180", "--size", "64x64", "--headless", "--frames", "1", "--out", "@out"},
      "out",
      {}};
}
const std::string kDome180 = (kSource / "configs/displays/dome180/display.json").string();
const std::string kDome180Warp = (kSource / "configs/displays/dome180/dome180.warp.exr").string();

void add_flags_render(std::vector<Variant>& out) {
  const Base b = render_base();
  add_flag_values(out, "render", b, "--display",
                  inputs(".json") + std::vector<std::string>{"builtin:", "builtin:bogus"});
  add_flag_values(out, "render", b, "--scene", scenes());
  add_flag_values(out, "render", b, "--method", choices("facets"));
  add_flag_values(out, "render", b, "--material", choices("lit") + inputs(".frag"));
  add_flag_values(out, "render", b, "--builder", choices("fewest"));
  add_flag_values(out, "render", b, "--eye", points());
  add_flag_values(out, "render", b, "--look-at", points(), {"--eye=0,1.6,0"});
  add_flag_values(out, "render", b, "--camera", names() + std::vector<std::string>{"nobody"});
  add_flag_values(out, "render", b, "--face-size", counts({"1000000"}), {"--method=cubemap"});
  add_flag_values(out, "render", b, "--size", sizes());
  add_flag_values(out, "render", b, "--frames", counts({"1000001"}));
  add_flag_values(out, "render", b, "--msaa", naturals({"4096"}));
  add_flag_values(out, "render", b, "--tilt", angles("91"));
  add_flag_values(out, "render", b, "--orientation", angles("361"));
  add_flag_values(out, "render", b, "--out", out_folders());
  add_flag_values(out, "render", b, "--reference-scene", scenes(), {"--reference"});
  add_flag_values(out, "render", b, "--anisotropy", non_negatives({"1000"}));
  add_flag_values(out, "render", b, "--coverage", choices("grid"));
  add_flag_values(out, "render", b, "--triangle-list", choices("auto"));
  add_flag_values(out, "render", b, "--pieces", counts({"100000000"}));
  add_flag_values(out, "render", b, "--grid", sizes({"65536x1", "1x65536"}));
  add_flag_values(out, "render", b, "--tolerance", positives({"1e-9", "1e-300"}));
}

void add_flags_run(std::vector<Variant>& out) {
  const Base b = run_base();
  const Base by_flag{
      {"run", "--size", "64x64", "--headless", "--frames", "1", "--out", "@out"}, "out", {}};
  add_flag_values(out, "run", by_flag, "--display",
                  inputs(".json") + std::vector<std::string>{"builtin:", "builtin:bogus"});
  add_flag_values(out, "run", b, "--scene", scenes());
  add_flag_values(out, "run", b, "--size", sizes());
  add_flag_values(out, "run", b, "--eye", points());
  add_flag_values(out, "run", b, "--look-at", points(), {"--eye=0,1.6,0"});
  add_flag_values(out, "run", b, "--camera", names() + std::vector<std::string>{"nobody"});
  add_flag_values(out, "run", b, "--method", choices("facets"));
  add_flag_values(out, "run", b, "--tolerance", positives({"1e-9", "1e-300"}));
  add_flag_values(out, "run", b, "--material", choices("lit") + inputs(".frag"));
  add_flag_values(out, "run", b, "--scale", positives({"1.5", "1e-9"}));
  add_flag_values(out, "run", b, "--tilt", angles("91"));
  add_flag_values(out, "run", b, "--orientation", angles("361"));
  add_flag_values(out, "run", b, "--frames", counts({"1000001"}));
  add_flag_values(out, "run", b, "--out", out_folders());
  add_flag_values(out, "run", b, "--pattern", choices("grid"));
  add_flag_values(out, "run", b, "--save-every", counts({"1000001"}));
  add_flag_values(out, "run", b, "--report", out_files(".json"));
  const Base cluster{{"run", "@display.json", "--headless", "--frames", "1", "--out", "@out"},
                     "out",
                     [](const fs::path& dir) {
                       display_context(dir);
                       spit(dir / "display.json", cluster_base(dir).dump(1));
                     }};
  add_flag_values(out, "run", cluster, "--node",
                  names() + std::vector<std::string>{"nobody", "MID"});
  add_flag_values(out, "run", cluster, "--join-timeout", positives({"1e9"}), {"--node=left"});
  add_flag_values(out, "run", cluster, "--rate", positives({"1e9"}), {"--node=left"});
}

// A valid 64×64 PNG, written once in a forked child (OpenImageIO's threads must not start here):
// the play flags' inputs are then written without it, in this process.
const std::string& still_png() {
  static const std::string bytes = [] {
    const fs::path path =
        fs::temp_directory_path() / ("facet_hostile_png_" + std::to_string(::getpid()));
    std::fflush(nullptr);
    const pid_t child = ::fork();
    if (child == 0) {
      spit(path, still_image(".png", 64, 64));
      ::_exit(0);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    std::string png = slurp(path);
    fs::remove(path);
    return png;
  }();
  return bytes;
}

void add_flags_play(std::vector<Variant>& out) {
  const Base b{{"play", "@x.png", "--headless", "--frames", "1", "--out", "@out"},
               "out",
               [](const fs::path& dir) { spit(dir / "x.png", still_png()); }};
  add_flag_values(out, "play", b, "--display",
                  inputs(".json") + std::vector<std::string>{"builtin:", "builtin:bogus"});
  add_flag_values(out, "play", b, "--size", sizes(), {"--display=builtin:dome180"});
  add_flag_values(out, "play", b, "--scale", positives({"1.5", "1e-9"}));
  add_flag_values(out, "play", b, "--format", choices("fisheye"));
  add_flag_values(out, "play", b, "--fov", positives({"361", "1e9"}));
  add_flag_values(out, "play", b, "--tilt", angles("91"));
  add_flag_values(out, "play", b, "--orientation", angles("361"));
  add_flag_values(out, "play", b, "--frames", counts({"1000001"}));
  add_flag_values(out, "play", b, "--start-frame", naturals());
  add_flag_values(out, "play", b, "--out", out_folders());
  add_flag_values(out, "play", b, "--stats", out_files(".jsonl"));
  // A cache folder: any folder facet may write in will do, so only paths that cannot be one.
  add_flag_values(out, "play", b, "--direction-cache",
                  {"",
                   "{dir}/fifo",
                   "{dir}/file",
                   "{dir}/file_link",
                   "{dir}/file/x",
                   "{dir}/file/x/y",
                   "{dir}/fifo/x",
                   "{dir}/" + kLongName,
                   "{dir}/cache/" + kLongName,
                   "{dir}/loop",
                   "{dir}/loop/x",
                   "{dir}/null_link",
                   "{dir}/null_dev",
                   "{dir}/null_dev/x",
                   "/dev/null",
                   "/dev/null/x",
                   "/proc/facet_hostile_out",
                   "/proc/facet_hostile_out/x",
                   "/sys/facet_hostile_out",
                   "/sys/facet_hostile_out/x"});
  add_flag_values(out, "play", b, "--direction-cache", {"{dir}/cache"}, {"--no-direction-cache"});
  add_flag_values(out, "play", b, "--direction-cache-budget", counts({"1048577", "1e12"}));
  add_flag_values(out, "play", b, "--direction-cache-budget", {"64"}, {"--no-direction-cache"});
  Base cluster = b;
  cluster.args = {"play",     "@x.png", "--display", "@display.json", "--headless",
                  "--frames", "1",      "--out",     "@out"};
  cluster.make = [](const fs::path& dir) {
    display_context(dir);
    spit(dir / "display.json", cluster_base(dir).dump(1));
    spit(dir / "x.png", still_png());
  };
  add_flag_values(out, "play", cluster, "--node", names() + std::vector<std::string>{"nobody"});
  add_flag_values(out, "play", cluster, "--join-timeout", positives({"1e9"}), {"--node=left"});
  add_flag_values(out, "play", cluster, "--rate", positives({"1e9"}), {"--node=left"});
}

void add_flags_preview_display_depth(std::vector<Variant>& out) {
  const Base preview{{"preview", kDome180, "--out", "@out.png"}, "out.png", {}};
  const Base builtin{{"preview", "builtin:dome180", "--out", "@out.png"}, "out.png", {}};
  const Base preview_by_flag{{"preview", "--out", "@out.png"}, "out.png", {}};
  add_flag_values(out, "preview", preview_by_flag, "--display",
                  inputs(".json") + std::vector<std::string>{"builtin:", "builtin:bogus"});
  add_flag_values(out, "preview", builtin, "--size", sizes());
  add_flag_values(out, "preview", preview, "--tilt", angles("91"));
  add_flag_values(out, "preview", preview, "--orientation", angles("361"));
  add_flag_values(out, "preview", preview, "--view", choices("fisheye"));
  add_flag_values(out, "preview", preview, "--fov", positives({"361", "1e9"}), {"--view=fisheye"});
  add_flag_values(out, "preview", preview, "--show", choices("blend"));
  add_flag_values(out, "preview", preview, "--preview-size", counts({"7", "8193"}));
  add_flag_values(out, "preview", preview, "--out", out_files(".png"));
  const Base display{{"display", "builtin:dome180", "--out", "@out"}, "out", {}};
  const Base display_by_flag{{"display", "--out", "@out"}, "out", {}};
  add_flag_values(out, "display", display_by_flag, "--display",
                  inputs(".json") + std::vector<std::string>{"builtin:", "builtin:bogus"});
  add_flag_values(out, "display", display, "--size", sizes());
  add_flag_values(out, "display", display, "--name", names());
  add_flag_values(out, "display", display, "--out", out_folders());
  add_flag_values(out, "display", display, "--tilt", angles("91"));
  add_flag_values(out, "display", display, "--orientation", angles("361"));
  const Base depth{{"depth-image", "--size", "32x32", "--out", "@out.exr"}, "out.exr", {}};
  add_flag_values(out, "depth-image", depth, "--scene", scenes());
  add_flag_values(out, "depth-image", depth, "--out", out_files(".exr"));
  add_flag_values(out, "depth-image", depth, "--kind", choices("dpci"));
  add_flag_values(out, "depth-image", depth, "--size", sizes());
  add_flag_values(out, "depth-image", depth, "--eye", points());
  const Base lookup{{"lookup", "--warp", kDome180Warp, "--out", "@out.exr"}, "out.exr", {}};
  add_flag_values(out, "lookup", lookup, "--out", out_files(".exr"));
  const Base lookup_bare{{"lookup", "--out", "@out.exr"}, "out.exr", {}};
  add_flag_values(out, "lookup", lookup_bare, "--warp", inputs(".warp.exr"));
  const Base lookup_display{{"lookup", "--out", "@out"}, "out", {}};
  add_flag_values(out, "lookup", lookup_display, "--display", inputs(".json"));
  const Base devices{{"devices"}, "out", {}};
  add_flag_values(out, "devices", devices, "--for", positives({"1e9"}), {"--watch"});
  add_flag_values(out, "devices", devices, "--find",
                  std::vector<std::string>{"",
                                           " ",
                                           "usb:",
                                           "usb:zzzz:0000",
                                           "usb:12345:0000",
                                           "usb:1234",
                                           "usb:1234:",
                                           "usb:1234:56789",
                                           "usb:-1:1",
                                           "pci:1234:5678",
                                           "usb:1234:5678@",
                                           "usb:1234:5678:",
                                           "\xff\xfe",
                                           "nan",
                                           "1e308",
                                           "-1",
                                           "usb:1234:5678:\xff",
                                           "usb::",
                                           "usb:0x12:0x34",
                                           "USB",
                                           "usb:1234:5678@\n"});
}

void add_flags_calibration(std::vector<Variant>& out) {
  const Base simulate{{"simulate", "--rig", "builtin:wall2x2", "--out", "@out"}, "out", {}};
  add_flag_values(out, "simulate", simulate, "--rig",
                  inputs(".json") + std::vector<std::string>{"builtin:", "builtin:bogus"});
  add_flag_values(out, "simulate", simulate, "--out", out_folders());
  add_flag_values(out, "simulate", simulate, "--noise", non_negatives({"2"}));
  add_flag_values(out, "simulate", simulate, "--defocus", non_negatives({"1e6"}));
  add_flag_values(out, "simulate", simulate, "--camera-blur", non_negatives({"1e6"}));
  add_flag_values(out, "simulate", simulate, "--ambient", non_negatives({"2"}));
  add_flag_values(out, "simulate", simulate, "--peak", positives({"2"}));
  add_flag_values(out, "simulate", simulate, "--gamma", positives({"1000"}));
  add_flag_values(out, "simulate", simulate, "--bits", counts({"9", "12"}));
  add_flag_values(out, "simulate", simulate, "--seed", unsigneds());
  add_flag_values(out, "simulate", simulate, "--phase-period", positives({"1e9"}));
  add_flag_values(out, "simulate", simulate, "--camera-size", sizes());
  const Base patterns{{"patterns", "--size", "64x32", "--out", "@out"}, "out", {}};
  add_flag_values(out, "patterns", patterns, "--size", sizes());
  add_flag_values(out, "patterns", patterns, "--out", out_folders());
  add_flag_values(out, "patterns", patterns, "--phase-period", positives({"1e9"}));
  add_flag_values(out, "patterns", patterns, "--phase-steps", counts({"2", "65"}));
  add_flag_values(out, "patterns", patterns, "--bit-depth", counts({"9", "12"}));
  const Base calibrate{{"calibrate", kCapture.string(), "--out", "@out"}, "out", {}};
  add_flag_values(out, "calibrate", calibrate, "--out", out_folders());
  add_flag_values(out, "calibrate", calibrate, "--grid", sizes({"1x1", "65536x1"}));
  add_flag_values(out, "calibrate", calibrate, "--node-spacing", positives({"1e-9"}));
  add_flag_values(out, "calibrate", calibrate, "--black-level", non_negatives({"1", "2"}));
  add_flag_values(out, "calibrate", calibrate, "--feather", non_negatives({"1e6"}));
  add_flag_values(out, "calibrate", calibrate, "--display", inputs(".json"));
  add_flag_values(out, "calibrate", calibrate, "--name", names());
}

void add_flags_capture(std::vector<Variant>& out) {
  const Base b{{"capture", "--display", "@display.json", "--camera", "fake:builtin:wall2x2",
                "--out", "@out", "--quiet", "--settle-ms", "0"},
               "out",
               [](const fs::path& dir) {
                 json projectors = json::array();
                 for (int i = 0; i < 4; ++i) {
                   projectors.push_back({{"name", "p" + std::to_string(i)},
                                         {"size", {1024, 576}},
                                         {"gamma", 2.2},
                                         {"output", {{"window", {1024 * i, 0, 1024, 576}}}}});
                 }
                 spit(dir / "display.json",
                      json{{"format", "facet-display/1"},
                           {"name", "hostile"},
                           {"eye", {0, 0, 0}},
                           {"render", {{"method", "naive"}, {"tolerance_px", 0.5}}},
                           {"missing_monitor", "window"},
                           {"projectors", projectors}}
                          .dump(1));
               }};
  Base no_display = b;
  no_display.args = {"capture", "--camera", "fake:builtin:wall2x2", "--out", "@out", "--quiet"};
  add_flag_values(out, "capture", no_display, "--display", inputs(".json"));
  Base no_camera = b;
  no_camera.args = {"capture", "--display", "@display.json", "--out", "@out", "--quiet"};
  add_flag_values(out, "capture", no_camera, "--camera",
                  std::vector<std::string>{"",
                                           "fake:",
                                           "fake:builtin:bogus",
                                           "fake:{dir}/missing.json",
                                           "fake:{dir}/dir",
                                           "fake:{dir}/fifo",
                                           "fake:/dev/zero",
                                           "fake:{dir}/empty",
                                           "fake:{dir}/garbage",
                                           "fake:{dir}/loop",
                                           "/dev/video999",
                                           "{dir}/file",
                                           "{dir}/fifo",
                                           "-1",
                                           "99999999999",
                                           "usb:",
                                           "usb:zzzz:0000",
                                           "\xff\xfe",
                                           "nan",
                                           "1e308",
                                           " "});
  add_flag_values(out, "capture", b, "--out", out_folders());
  add_flag_values(out, "capture", b, "--camera-model", inputs(".cameramodel"));
  add_flag_values(out, "capture", b, "--camera-pose", inputs(".json"));
  add_flag_values(out, "capture", b, "--camera-size", sizes());
  add_flag_values(out, "capture", b, "--camera-gamma", positives({"1000"}));
  add_flag_values(out, "capture", b, "--projector-gamma", positives({"1000"}));
  add_flag_values(out, "capture", b, "--average", counts({"1000001"}));
  add_flag_values(out, "capture", b, "--settle-ms", naturals({"100000000"}));
  add_flag_values(out, "capture", b, "--discard", naturals({"100000000"}));
  add_flag_values(out, "capture", b, "--bits", counts({"9", "12"}));
  add_flag_values(out, "capture", b, "--phase-period", positives({"1e9"}));
  add_flag_values(out, "capture", b, "--phase-steps", counts({"2", "65"}));
  add_flag_values(out, "capture", b, "--max-clipped", non_negatives({"2"}));
  add_flag_values(out, "capture", b, "--stop-after", unsigneds());
}

void add_flags_interop(std::vector<Variant>& out) {
  const Base bourke{{"bourke", "import", kBourke.string(), "--out", "@out"}, "out", {}};
  add_flag_values(out, "bourke import", bourke, "--out", out_folders());
  add_flag_values(out, "bourke import", bourke, "--size", sizes({"1000x1000"}));
  add_flag_values(out, "bourke import", bourke, "--fov", positives({"361", "1e9"}));
  add_flag_values(out, "bourke import", bourke, "--grid", sizes({"1x1", "65536x1"}));
  add_flag_values(out, "bourke import", bourke, "--intensity-gamma", positives({"1000"}));
  add_flag_values(out, "bourke import", bourke, "--zenith", choices("centre"));
  add_flag_values(out, "bourke import", bourke, "--tilt", angles("91"));
  add_flag_values(out, "bourke import", bourke, "--orientation", angles("361"));
  // A tile screen: every bad value is refused before the build.
  const Base tiles{
      {"tiles", (kSource / "configs/tiles/panorama-360.json").string(), "--out", "@out"},
      "out",
      {}};
  add_flag_values(out, "tiles", tiles, "--out", out_folders());
  add_flag_values(out, "tiles", tiles, "--size", sizes({"1000x1000", "1x1"}));
  add_flag_values(out, "tiles", tiles, "--tolerance", positives({"16385", "1e9"}));
  // A display both exports take (dome180's footprints are wider than one frustum holds).
  const std::string wall = (kSource / "configs/displays/wall2x2/display.json").string();
  const Base mpcdi_export{{"mpcdi", "export", wall, "--out", "@out.mpcdi"}, "out.mpcdi", {}};
  const Base mpcdi_export_by_flag{{"mpcdi", "export", "--out", "@out.mpcdi"}, "out.mpcdi", {}};
  add_flag_values(out, "mpcdi export", mpcdi_export_by_flag, "--display", inputs(".json"));
  add_flag_values(out, "mpcdi export", mpcdi_export, "--out", out_files(".mpcdi"));
  add_flag_values(out, "mpcdi export", mpcdi_export, "--node-spacing", positives({"1e-9"}));
  add_flag_values(out, "mpcdi export", mpcdi_export, "--profile", choices("3d"));
  const Base mpcdi_import{{"mpcdi", "import", kMpcdi.string(), "--out", "@out"}, "out", {}};
  add_flag_values(out, "mpcdi import", mpcdi_import, "--out", out_folders());
  add_flag_values(out, "mpcdi import", mpcdi_import, "--warp-values", choices("auto"));
  add_flag_values(out, "mpcdi import", mpcdi_import, "--grid", sizes({"1x1", "65536x1"}));
  add_flag_values(out, "mpcdi import", mpcdi_import, "--eye", points());
  add_flag_values(out, "mpcdi import", mpcdi_import, "--tilt", angles("91"));
  add_flag_values(out, "mpcdi import", mpcdi_import, "--orientation", angles("361"));
  const Base sgct_export{{"sgct", "export", wall, "--out", "@out"}, "out", {}};
  const Base sgct_export_by_flag{{"sgct", "export", "--out", "@out"}, "out", {}};
  add_flag_values(out, "sgct export", sgct_export_by_flag, "--display", inputs(".json"));
  add_flag_values(out, "sgct export", sgct_export, "--out", out_folders());
  add_flag_values(out, "sgct export", sgct_export, "--node-spacing", positives({"1e-9"}));
  add_flag_values(out, "sgct export", sgct_export, "--mask-gamma", positives({"1000"}));
  const Base sgct_import{{"sgct", "import", kSgc.string(), "--out", "@out"}, "out", {}};
  add_flag_values(out, "sgct import", sgct_import, "--out", out_folders());
  add_flag_values(out, "sgct import", sgct_import, "--size", sizes());
  add_flag_values(out, "sgct import", sgct_import, "--grid", sizes({"1x1", "65536x1"}));
  add_flag_values(out, "sgct import", sgct_import, "--mask-gamma", positives({"1000"}));
  add_flag_values(out, "sgct import", sgct_import, "--tilt", angles("91"));
  add_flag_values(out, "sgct import", sgct_import, "--orientation", angles("361"));
}

void add_flags_error_bench(std::vector<Variant>& out) {
  // Small, so that a value taken as valid costs little (at the default 1600x1200: 3 s).
  const Base error{{"error", "--size", "160x120"}, "out", {}};
  add_flag_values(out, "error", error, "--warp", inputs(".warp.exr"));
  add_flag_values(out, "error", error, "--base", choices("fisheye"));
  add_flag_values(out, "error", error, "--size", sizes());
  add_flag_values(out, "error", error, "--azimuth", pairs({"5,5", "-400,400"}));
  // Top below bottom ("-1,1") is a valid, upside-down cylinder; these are not.
  add_flag_values(out, "error", error, "--tan-elevation", pairs({"1,1", "0,-0", "1e9,-1"}));
  add_flag_values(out, "error", error, "--elevation", pairs({"10,10", "100,-100"}),
                  {"--base=equirectangular"});
  add_flag_values(out, "error", error, "--tan-extent",
                  pairs({"1,1,1,1", "-1,1,1", "-1,1,1,-1,5", "nan,1,1,-1", "-1,1,1,inf"}),
                  {"--base=perspective"});
  add_flag_values(out, "error", error, "--fov", positives({"361", "1e9"}), {"--base=fisheye"});
  add_flag_values(out, "error", error, "--builder", choices("fewest"));
  add_flag_values(out, "error", error, "--pieces", counts({"100000000"}));
  add_flag_values(out, "error", error, "--grid", sizes({"65536x1", "1x65536"}));
  add_flag_values(out, "error", error, "--tolerance", positives({"1e-9", "1e-300"}));
  // One frame at a tenth of --quick's sizes: 2.5 s when a value is taken as valid (50 s without).
  const Base bench{{"bench", "--quick", "--scenario", "cylinder", "--frames", "1", "--size-scale",
                    "0.1", "--out", "@out"},
                   "out",
                   {}};
  add_flag_values(out, "bench", bench, "--scenario", choices("cylinder"));
  add_flag_values(out, "bench", bench, "--frames", counts({"1000001"}));
  add_flag_values(out, "bench", bench, "--size-scale", positives({"1e-9", "1000"}));
  add_flag_values(out, "bench", bench, "--out", out_folders());
  // The rig is the dome4 scenario's: that scenario instead of cylinder (given twice, the
  // scenario alone would be refused).
  Base bench_dome4 = bench;
  bench_dome4.args[3] = "dome4";
  add_flag_values(out, "bench", bench_dome4, "--rig",
                  inputs(".json") + std::vector<std::string>{"builtin:", "builtin:bogus"});
  add_flag_values(out, "bench", bench, "--scene", scenes());
  add_flag_values(out, "bench", bench, "--eye", points());
  add_flag_values(out, "bench", bench, "--look-at", points(), {"--eye=0,1.6,0"});
  add_flag_values(out, "bench", bench, "--camera", names() + std::vector<std::string>{"nobody"});
}

// Every input kind with its generator: one test each, its variants run in turn (one process per
// kind keeps ctest's per-test start-up out of the suite's time).
struct Kind {
  const char* name;
  void (*add)(std::vector<Variant>&);
};

// gtest prints a parameter with this (instead of its bytes).
void PrintTo(const Kind& kind, std::ostream* stream) { *stream << kind.name; }

const Kind kKinds[] = {
    {"flags", add_flags},
    {"display_json", add_display_json},
    {"warp_exr", add_warp_exr},
    {"blend_exr", add_blend_exr},
    {"rig_json", add_rig_json},
    {"glc_json", add_glc_json},
    {"capture_and_cameramodel", add_capture},
    {"mpcdi_and_pfm", add_mpcdi},
    {"bourke_data", add_bourke},
    {"sgc", add_sgc},
    {"cluster_xml_and_simcad", add_cluster},
    {"gltf", add_gltf},
    {"play_content", add_play_content},
    {"material_frag", add_material},
    {"cluster_section_and_node", add_cluster_section},
    {"depth_image", add_depth_image},
    {"flags_render", add_flags_render},
    {"flags_run", add_flags_run},
    {"flags_play", add_flags_play},
    {"flags_preview_display_depth_lookup_devices", add_flags_preview_display_depth},
    {"flags_simulate_patterns_calibrate", add_flags_calibration},
    {"flags_capture", add_flags_capture},
    {"flags_bourke_mpcdi_sgct", add_flags_interop},
    {"flags_error_bench", add_flags_error_bench},
};

// ---- Running one variant ------------------------------------------------------------------------

struct Outcome {
  int exit_code = -1;  // -1 when a signal ended it
  int signal = 0;
  bool timed_out = false;
  long max_resident_kib = 0;
  std::string stderr_text;
};

// The threads of this process.
std::size_t thread_count() {
  std::error_code ec;
  const auto tasks = fs::directory_iterator("/proc/self/task", ec);
  return ec ? std::size_t(-1) : std::size_t(std::distance(fs::begin(tasks), fs::end(tasks)));
}

// Those the shared libraries' initialisers start before main (log4cplus, loaded with OpenCV,
// starts an idle pool of 4), which every facet process has too and facet never calls.
const std::size_t kStartupThreads = thread_count();

// A fork copies only the calling thread, so the CLI runs in a forked child only while no other
// thread has started since (OpenEXR's pool, once a variant's files are written with it), whose
// locks the child could inherit held.
bool single_threaded() { return thread_count() <= kStartupThreads; }

// Runs facet with `args` in `cwd`, under the limits, stderr to `log`: calling facet::cli::run in a
// forked child (the same code as the executable's main, without the dynamic loader's 0.15 s of
// CPU per start, which 4,000 variants cannot afford), or exec'ing the executable while other
// threads run in this process.
Outcome run_cli(const std::vector<std::string>& args, const fs::path& cwd, const fs::path& log) {
  bool in_process = true;
  if (!single_threaded()) {
    static bool told = false;
    if (!std::exchange(told, true)) std::cout << "other threads running: exec'ing facet instead\n";
    in_process = false;
  }
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  std::vector<std::string> storage{"facet"};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (std::string& a : storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  const pid_t child = ::fork();
  if (child == 0) {
    ::setpgid(0, 0);
#ifndef __SANITIZE_ADDRESS__  // ASan reserves terabytes of address space; max RSS still checked
    const rlimit limit{kAddressSpaceLimit, kAddressSpaceLimit};
    ::setrlimit(RLIMIT_AS, &limit);
#endif
    const rlimit no_core{0, 0};
    ::setrlimit(RLIMIT_CORE, &no_core);
    if (::chdir(cwd.c_str()) != 0) ::_exit(126);
    const int null = ::open("/dev/null", O_RDWR);
    const int err = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    ::dup2(null, 0);
    ::dup2(null, 1);
    ::dup2(err, 2);
    ::unsetenv("DISPLAY");
    ::unsetenv("WAYLAND_DISPLAY");
    if (in_process) {
      // Ends as main() would, less the static destructors: those of the libraries' pools
      // (log4cplus's) would wait for threads that the fork did not copy.
      const int status = facet::cli::run(static_cast<int>(storage.size()), argv.data());
      std::cout.flush();
      std::cerr.flush();
      std::fflush(nullptr);
      ::_exit(status);
    }
    ::execv(FACET_CLI, argv.data());
    ::_exit(127);
  }
  Outcome outcome;
  const auto deadline = std::chrono::steady_clock::now() + kWallLimit;
  int status = 0;
  rusage usage{};
  // Woken by the child's end through a pidfd (a refused flag ends within a millisecond or two);
  // without one, polled from 0.1 ms up to 5 ms.
  const int pidfd = static_cast<int>(::syscall(SYS_pidfd_open, child, 0));
  auto poll = std::chrono::microseconds(100);
  for (;;) {
    const pid_t done = ::wait4(child, &status, WNOHANG, &usage);
    if (done == child) break;
    const auto now = std::chrono::steady_clock::now();
    if (now > deadline) {
      outcome.timed_out = true;
      ::kill(-child, SIGKILL);
      ::kill(child, SIGKILL);
      ::wait4(child, &status, 0, &usage);
      break;
    }
    if (pidfd >= 0) {
      pollfd ended{pidfd, POLLIN, 0};
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - now);
      ::poll(&ended, 1, static_cast<int>(std::min<std::int64_t>(left.count() + 1, 1000)));
    } else {
      std::this_thread::sleep_for(poll);
      poll = std::min<std::chrono::microseconds>(poll * 2, std::chrono::milliseconds(5));
    }
  }
  if (pidfd >= 0) ::close(pidfd);
  ::kill(-child, SIGKILL);  // anything it left running in its group
  if (WIFEXITED(status)) outcome.exit_code = WEXITSTATUS(status);
  if (WIFSIGNALED(status)) outcome.signal = WTERMSIG(status);
  outcome.max_resident_kib = usage.ru_maxrss;
  outcome.stderr_text = slurp(log);
  return outcome;
}

// Hidden temporaries (.NAME.tmp*) anywhere under `dir`; symbolic links are not followed.
std::vector<std::string> leftover_temporaries(const fs::path& dir) {
  std::vector<std::string> found;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::end(it);
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.starts_with(".") && name.find(".tmp") != std::string::npos) {
      found.push_back(it->path().string());
    }
  }
  return found;
}

void check_variant(const Variant& variant) {
#ifdef __SANITIZE_ADDRESS__
  if (address_limited().contains(variant.name)) return;
#endif
  const fs::path root = fs::temp_directory_path() / ("facet_hostile_" + std::to_string(::getpid()));
  const fs::path scratch = root / variant.name;
  std::error_code ec;
  fs::remove_all(scratch, ec);
  fs::create_directories(scratch);
  // In a forked child: writing the inputs (with OpenImageIO, OpenEXR, OpenCV) starts pools of
  // threads, which must not run here for the CLI to run in forked children of this process.
  if (variant.make && !variant.make_starts_threads) variant.make(scratch);
  if (variant.make && variant.make_starts_threads) {
    std::fflush(nullptr);
    const pid_t child = ::fork();
    if (child == 0) {
      int status = 0;
      try {
        variant.make(scratch);
      } catch (...) {
        status = 1;
      }
      std::fflush(nullptr);
      ::_exit(status);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    ASSERT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "writing the inputs failed";
  }
  std::vector<std::string> args;
  for (const std::string& a : variant.args) {
    args.push_back(replace_all(a.starts_with("@") ? (scratch / a.substr(1)).string() : a, "{dir}",
                               scratch.string()));
  }
  const auto started = std::chrono::steady_clock::now();
  const Outcome outcome = run_cli(args, scratch, root / (variant.name + ".stderr"));
  // Reported, not asserted (the machine's load sets it): a refusal takes milliseconds.
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  if (seconds > 1.0) std::cout << "  slow: " << variant.name << " " << seconds << " s\n";
  std::string command = "facet";
  for (const std::string& a : args) command += " " + a;
  SCOPED_TRACE(command + "\nstderr: " + outcome.stderr_text);

  EXPECT_FALSE(outcome.timed_out) << "ran past " << kWallLimit.count() << " s";
  EXPECT_EQ(outcome.signal, 0) << "killed by signal " << outcome.signal;
  EXPECT_EQ(outcome.exit_code, 2);
  EXPECT_LT(outcome.max_resident_kib, kMaxResidentKiB);
  EXPECT_EQ(outcome.stderr_text.find("internal error"), std::string::npos);
  // A flag's or a field's name counts only outside the scratch folder's path, which holds the
  // variant's name (and so the flag's, when it has no '-'); a path counts anywhere.
  const std::string stderr_outside_scratch =
      replace_all(outcome.stderr_text, scratch.string(), "SCRATCH");
  const bool named =
      std::any_of(variant.mentions.begin(), variant.mentions.end(), [&](const std::string& m) {
        const bool path = m.find("{dir}") != std::string::npos || m.starts_with("/");
        const std::string bare =
            replace_all(m.starts_with("--") ? m.substr(2) : m, "{dir}", scratch.string());
        const std::string& text = path ? outcome.stderr_text : stderr_outside_scratch;
        return !bare.empty() && text.find(bare) != std::string::npos;
      });
  EXPECT_TRUE(named) << "stderr names none of the input or field";
  EXPECT_FALSE(fs::exists(fs::symlink_status(scratch / variant.output)))
      << variant.output << " left behind";
  EXPECT_TRUE(leftover_temporaries(scratch).empty()) << "a hidden temporary left behind";
  EXPECT_FALSE(fs::exists(fs::symlink_status(root / "escape")));
  if (with_fixtures().contains(variant.name)) {
    EXPECT_TRUE(fixtures_intact(scratch)) << "a file or folder of the user's changed";
  }
  fs::remove_all(scratch, ec);
  fs::remove(root / (variant.name + ".stderr"), ec);
  if (fs::is_empty(root, ec)) fs::remove(root, ec);
}

class Hostile : public ::testing::TestWithParam<Kind> {};

TEST_P(Hostile, EveryVariantExitsTwoNamingTheInputAndLeavesNothing) {
  std::vector<Variant> variants;
  GetParam().add(variants);
  EXPECT_GE(variants.size(), 20u);
  std::cout << GetParam().name << ": " << variants.size() << " variants\n";
  // Each flag a kind covers: at least 20 bad values.
  std::map<std::string, std::size_t> per_flag;
  for (const Variant& variant : variants) {
    if (flag_of().contains(variant.name)) ++per_flag[flag_of().at(variant.name)];
  }
  for (const auto& [flag, count] : per_flag) {
    std::cout << "  " << flag << ": " << count << " variants\n";
    EXPECT_GE(count, 20u) << flag;
  }
  // FACET_HOSTILE_EVERY=K runs variants 0, K, 2K, ... only (tools/dev test's sanitizer stage,
  // where every variant starts an instrumented process; the normal build runs them all).
  std::size_t every = 1;
  if (const char* text = std::getenv("FACET_HOSTILE_EVERY")) {
    every = std::size_t(std::max(1, std::atoi(text)));
  }
  std::size_t ran = 0;
  for (std::size_t k = 0; k < variants.size(); k += every) {
    SCOPED_TRACE("variant " + variants[k].name);
    check_variant(variants[k]);
    ++ran;
  }
  std::cout << "ran " << ran << " of " << variants.size() << " variants"
            << (every > 1 ? " (every " + std::to_string(every) + "th: FACET_HOSTILE_EVERY)" : "")
            << "\n";
}

INSTANTIATE_TEST_SUITE_P(Inputs, Hostile, ::testing::ValuesIn(kKinds),
                         [](const ::testing::TestParamInfo<Kind>& param) {
                           return std::string(param.param.name);
                         });

// Every value-taking flag of every command (as the CLI itself lists them) has at least 20 of the
// variants above: a flag added without its bad values fails here.
TEST(HostileFlags, EveryValueTakingFlagOfEveryCommandHasTwentyVariants) {
  CLI::App app;
  for (auto& [order, setup] : facet::cli::CommandRegistry::commands()) setup(app);
  std::set<std::string> flags;
  std::function<void(CLI::App*, const std::string&)> walk = [&](CLI::App* command,
                                                                const std::string& path) {
    for (const CLI::Option* option : command->get_options()) {
      if (option->get_expected_max() == 0 || option->get_lnames().empty()) continue;
      flags.insert(path + " --" + option->get_lnames().front());
    }
    for (CLI::App* sub : command->get_subcommands([](CLI::App*) { return true; })) {
      const std::string name = sub->get_name();
      walk(sub, name.empty() ? path : (path.empty() ? name : path + " " + name));
    }
  };
  walk(&app, "");
  ASSERT_GT(flags.size(), 100u);
  std::vector<Variant> variants;
  for (const Kind& kind : kKinds) {
    if (std::string(kind.name).starts_with("flags_")) kind.add(variants);
  }
  std::map<std::string, std::size_t> per_flag;
  for (const Variant& variant : variants) ++per_flag[flag_of().at(variant.name)];
  std::size_t total = 0;
  for (const std::string& flag : flags) {
    EXPECT_GE(per_flag[flag], 20u) << flag;
    total += per_flag[flag];
  }
  for (const auto& [flag, count] : per_flag) EXPECT_TRUE(flags.contains(flag)) << flag;
  std::cout << flags.size() << " value-taking flags, " << total << " variants\n";
}

}  // namespace
