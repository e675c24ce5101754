// Orbiting planets: a sun and three planets built from this program's own arrays (no glTF),
// moved every frame through facet's API, on the built-in 180° dome (looking up at the zenith).
//
//   orbiting_planets [--display NAME] [--size N] [--frames N] [--out DIR] [--headless]
//
// Headless (the default without a display server, or with --headless) it writes
// DIR/<output>_<frame>.png for every projector; with a display server it opens a window and
// shows the first projector's output until the window closes (or --frames frames).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <facet/facet.hpp>
#include <filesystem>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_precision.hpp>
#include <numbers>
#include <string>
#include <vector>

namespace {

struct Sphere {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs;
  std::vector<std::uint32_t> indices;
};

// A latitude-longitude sphere of `radius` metres: `rings` bands, `segments` slices, outward
// counter-clockwise triangles, u along the longitude, v from the north pole.
Sphere make_sphere(float radius, int rings, int segments) {
  Sphere s;
  for (int r = 0; r <= rings; ++r) {
    const double polar = std::numbers::pi * r / rings;
    for (int k = 0; k <= segments; ++k) {
      const double azimuth = 2 * std::numbers::pi * k / segments;
      const glm::vec3 n(float(std::sin(polar) * std::cos(azimuth)), float(std::cos(polar)),
                        float(-std::sin(polar) * std::sin(azimuth)));
      s.positions.push_back(radius * n);
      s.normals.push_back(n);
      s.uvs.emplace_back(float(k) / float(segments), float(r) / float(rings));
    }
  }
  const auto at = [&](int r, int k) { return std::uint32_t(r * (segments + 1) + k); };
  for (int r = 0; r < rings; ++r)
    for (int k = 0; k < segments; ++k) {
      for (std::uint32_t i : {at(r, k), at(r + 1, k), at(r + 1, k + 1)}) s.indices.push_back(i);
      for (std::uint32_t i : {at(r, k), at(r + 1, k + 1), at(r, k + 1)}) s.indices.push_back(i);
    }
  return s;
}

// Bands of two colours, `bands` of them from pole to pole: a planet's surface.
std::vector<std::uint8_t> banded_texture(int size, int bands, glm::u8vec3 a, glm::u8vec3 b) {
  std::vector<std::uint8_t> rgba;
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      const glm::u8vec3 c = (y * bands / size) % 2 ? a : b;
      rgba.insert(rgba.end(), {c.x, c.y, c.z, 255});
    }
  return rgba;
}

struct Options {
  std::string display = "builtin:dome180";
  int size = 512;
  int frames = 5;
  bool frames_given = false;
  std::string out = "orbiting_planets_frames";
  bool headless = false;
};

Options parse(int argc, char** argv) {
  Options options;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    const auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "%s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--display")
      options.display = value();
    else if (arg == "--size")
      options.size = std::stoi(value());
    else if (arg == "--frames")
      options.frames = std::stoi(value()), options.frames_given = true;
    else if (arg == "--out")
      options.out = value();
    else if (arg == "--headless")
      options.headless = true;
    else {
      std::fprintf(stderr,
                   "usage: %s [--display NAME] [--size N] [--frames N] [--out DIR] "
                   "[--headless]\n",
                   argv[0]);
      std::exit(2);
    }
  }
  return options;
}

}  // namespace

int main(int argc, char** argv) try {
  const Options options = parse(argc, argv);
  const char* x_display = std::getenv("DISPLAY");
  const bool windowed = !options.headless && x_display && *x_display;

  // The display first: its size decides the window's.
  const facet::Display display =
      facet::Display::open(options.display, glm::ivec2(options.size, options.size));
  facet::Context context = windowed
                               ? facet::Context::window(display.output_size(0), "orbiting planets")
                               : facet::Context::headless();
  std::printf("GL: %s\n", context.renderer().c_str());

  // The scene from our own arrays: one sphere mesh per material, instanced by the objects.
  facet::SceneBuilder builder;
  const Sphere sphere = make_sphere(1.0f, 24, 48);
  const facet::MeshData mesh{sphere.positions, sphere.normals, sphere.uvs, sphere.indices};
  const int sun_material =
      builder.add_material({.base_colour = {1.0f, 0.8f, 0.3f, 1}, .unlit = true});
  const int sun_mesh = builder.add_mesh(mesh, sun_material);
  struct Planet {
    double orbit_m, period_s, radius_m, phase;
    glm::u8vec3 a, b;
    facet::ObjectId object = 0;
  };
  std::vector<Planet> planets = {{1.1, 4.0, 0.25, 0.0, {40, 90, 220}, {60, 180, 90}},
                                 {1.7, 7.0, 0.4, 2.1, {200, 120, 60}, {240, 200, 150}},
                                 {2.4, 11.0, 0.3, 4.2, {180, 60, 60}, {90, 30, 30}}};
  const glm::dvec3 centre(0, 2.5, 0);  // 2.5 m above the eye: the dome's zenith
  const facet::ObjectId sun = builder.add_object(
      sun_mesh, glm::scale(glm::translate(glm::dmat4(1.0), centre), glm::dvec3(0.5)), "sun");
  for (std::size_t k = 0; k < planets.size(); ++k) {
    const std::vector<std::uint8_t> rgba =
        banded_texture(64, 6 + 2 * int(k), planets[k].a, planets[k].b);
    const int texture = builder.add_texture({64, 64, rgba});
    const int material = builder.add_material({.texture = texture, .unlit = true});
    planets[k].object = builder.add_object(builder.add_mesh(mesh, material), glm::dmat4(1.0),
                                           "planet" + std::to_string(k));
  }
  facet::Renderer renderer(display, std::move(builder).build());
  std::filesystem::create_directories(options.out);

  for (int frame = 0; !windowed || !options.frames_given || frame < options.frames; ++frame) {
    if (!windowed && frame >= options.frames) break;
    const double t = frame / 10.0;  // seconds: 10 frames a second of orbit
    renderer.set_frame(
        {.frame = std::uint64_t(frame), .time_s = t, .T_world_eye = glm::dmat4(1.0)});
    renderer.set_object_transform(
        sun, glm::rotate(glm::scale(glm::translate(glm::dmat4(1.0), centre), glm::dvec3(0.5)), t,
                         glm::dvec3(0, 1, 0)));
    for (const Planet& p : planets) {
      const double angle = p.phase + 2 * std::numbers::pi * t / p.period_s;
      const glm::dvec3 at =
          centre + p.orbit_m * glm::dvec3(std::cos(angle), 0.15 * std::sin(angle), std::sin(angle));
      renderer.set_object_transform(
          p.object,
          glm::scale(glm::rotate(glm::translate(glm::dmat4(1.0), at), 3 * t, glm::dvec3(0, 1, 0)),
                     glm::dvec3(p.radius_m)));
    }
    const facet::FrameReport report = renderer.render();
    if (windowed) {
      const glm::ivec2 size = renderer.output_size(0);
      renderer.present(0, {0, 0, size.x, size.y});
      context.swap();
      if (context.should_close()) break;
      continue;
    }
    for (std::size_t o = 0; o < renderer.output_count(); ++o) {
      char name[64];
      std::snprintf(name, sizeof name, "%s_%03d.png", report.outputs[o].name.c_str(), frame);
      renderer.write_output_png(o, std::filesystem::path(options.out) / name);
    }
    std::printf("frame %d: %.1f ms, %llu triangle draws\n", frame, report.cpu_ms,
                static_cast<unsigned long long>(report.outputs[0].replicas));
  }
  if (!windowed) std::printf("frames written to %s\n", options.out.c_str());
  return 0;
} catch (const std::exception& e) {
  std::fprintf(stderr, "orbiting_planets: %s\n", e.what());
  return 2;
}
