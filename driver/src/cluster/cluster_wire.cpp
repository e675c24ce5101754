// The cluster's wire format: FrameState in a versioned binary encoding, and digests.
#include <bit>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "facet/driver/cluster.hpp"
#include "facet/projection/errors.hpp"

namespace facet::driver {

static_assert(std::endian::native == std::endian::little,
              "the cluster wire format is little-endian, as every supported host");

namespace {

constexpr char kMagic[4] = {'F', 'S', 'T', 'A'};

class Writer {
 public:
  template <typename T>
  void put(const T& value) {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(&value);
    out_.insert(out_.end(), bytes, bytes + sizeof value);
  }
  void put(const glm::dmat4& m) {
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) put(m[c][r]);
  }
  std::vector<std::uint8_t> take() { return std::move(out_); }

 private:
  std::vector<std::uint8_t> out_;
};

class Reader {
 public:
  Reader(std::span<const std::uint8_t> bytes, const std::string& source)
      : bytes_(bytes), source_(source) {}

  template <typename T>
  T get(const std::string& field) {
    if (bytes_.size() - at_ < sizeof(T))
      throw InputError(source_, field,
                       "a complete frame state, but the message ends after " +
                           std::to_string(bytes_.size()) + " bytes");
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof value);
    at_ += sizeof value;
    return value;
  }
  double get_finite(const std::string& field) {
    const double value = get<double>(field);
    if (!std::isfinite(value)) throw InputError(source_, field, "a finite number");
    return value;
  }
  glm::dmat4 get_matrix(const std::string& field) {
    glm::dmat4 m(1.0);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) m[c][r] = get_finite(field);
    return m;
  }
  std::size_t left() const { return bytes_.size() - at_; }
  const std::string& source() const { return source_; }

 private:
  std::span<const std::uint8_t> bytes_;
  std::size_t at_ = 0;
  const std::string& source_;
};

constexpr std::size_t kMatrixBytes = 16 * sizeof(double);

}  // namespace

std::vector<std::uint8_t> encode_frame_state(const FrameState& state) {
  // Names every member: a member added to FrameState breaks this line until it is encoded here
  // (and decoded below), and the version goes up.
  const auto& [frame, time_s, T_world_eye, object_poses] = state;
  Writer out;
  for (const char c : kMagic) out.put(c);
  out.put(kFrameStateWireVersion);
  out.put(frame);
  out.put(time_s);
  out.put(T_world_eye);
  out.put(static_cast<std::uint32_t>(object_poses.size()));
  for (const ObjectPose& pose : object_poses) {
    const auto& [object, T_world_object] = pose;
    out.put(object);
    out.put(T_world_object);
  }
  return out.take();
}

FrameState decode_frame_state(std::span<const std::uint8_t> bytes, const std::string& source) {
  Reader in(bytes, source);
  for (const char c : kMagic) {
    if (in.get<char>("magic") != c)
      throw InputError(source, "magic", "a facet frame state (\"FSTA\")");
  }
  const auto version = in.get<std::uint16_t>("version");
  if (version != kFrameStateWireVersion)
    throw InputError(source, "version",
                     "frame state version " + std::to_string(kFrameStateWireVersion) +
                         " (this facet's), got " + std::to_string(version) +
                         ": run the same facet on every node");
  FrameState state;
  state.frame = in.get<std::uint64_t>("frame");
  state.time_s = in.get_finite("time_s");
  state.T_world_eye = in.get_matrix("T_world_eye");
  const auto poses = in.get<std::uint32_t>("object_poses");
  // Refused before anything is allocated for them.
  if (poses > kMaxObjectPoses || in.left() < std::size_t(poses) * (4 + kMatrixBytes))
    throw InputError(source, "object_poses",
                     "at most " + std::to_string(kMaxObjectPoses) +
                         " object poses, all in the message; it says " + std::to_string(poses) +
                         " in " + std::to_string(bytes.size()) + " bytes");
  state.object_poses.reserve(poses);
  for (std::uint32_t i = 0; i < poses; ++i) {
    ObjectPose pose;
    pose.object = in.get<std::uint32_t>("object_poses.object");
    pose.T_world_object = in.get_matrix("object_poses.T_world_object");
    state.object_poses.push_back(pose);
  }
  if (in.left() != 0)
    throw InputError(source, "",
                     "a frame state of " + std::to_string(bytes.size() - in.left()) +
                         " bytes, but " + std::to_string(in.left()) + " more bytes follow it");
  return state;
}

Digest& Digest::add(std::span<const std::uint8_t> bytes) {
  for (const std::uint8_t byte : bytes) {
    value_ ^= byte;
    value_ *= 0x100000001b3ull;
  }
  return *this;
}

Digest& Digest::add(std::string_view text) {
  add(std::span(reinterpret_cast<const std::uint8_t*>(text.data()), text.size()));
  const std::uint64_t size = text.size();
  return add(std::span(reinterpret_cast<const std::uint8_t*>(&size), sizeof size));
}

Digest& Digest::add_file(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw InputError(path.string(), "", "a readable file");
  std::vector<char> buffer(1 << 16);
  std::uint64_t size = 0;
  while (stream) {
    stream.read(buffer.data(), std::streamsize(buffer.size()));
    const auto got = static_cast<std::size_t>(stream.gcount());
    add(std::span(reinterpret_cast<const std::uint8_t*>(buffer.data()), got));
    size += got;
  }
  return add(std::span(reinterpret_cast<const std::uint8_t*>(&size), sizeof size));
}

std::string digest_hex(std::uint64_t digest) {
  char text[17];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(digest));
  return text;
}

std::uint64_t frame_state_digest(const FrameState& state) {
  return Digest().add(encode_frame_state(state)).value();
}

std::uint64_t content_digest(const projection_io::DisplayConfig& display,
                             const std::filesystem::path& display_file,
                             const std::string& scene_name,
                             const std::optional<std::filesystem::path>& scene_file,
                             const std::string& settings) {
  Digest digest;
  digest.add_file(display_file);
  for (const projection_io::DisplayProjector& projector : display.projectors) {
    digest.add(projector.name);
    digest.add_file(display.resolve(projector.warp));
    if (projector.blend) digest.add_file(display.resolve(*projector.blend));
    if (projector.black) digest.add_file(display.resolve(*projector.black));
  }
  digest.add(scene_name);
  if (scene_file) digest.add_file(*scene_file);
  digest.add(settings);
  return digest.value();
}

}  // namespace facet::driver
