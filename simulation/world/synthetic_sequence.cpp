// Scripted synthetic sequences (synthetic_sequence.hpp).
#include "simulation/world/synthetic_sequence.hpp"

#include <cmath>
#include <utility>

#include "core/assert.hpp"

namespace orthoflow::simulation {
namespace {

constexpr double PI = 3.14159265358979323846;
constexpr double FRAME_S = 1.0 / static_cast<double>(SEQUENCE_RATE_HZ);
constexpr double CLEARANCE_M = 0.01;
constexpr int PATH_ATTEMPTS = 100;

/// Whether @p mover stays on the table and clear of every other object at every frame.
bool path_is_clear(const SequenceScript& s, const ScriptedObject& mover) {
  for (std::uint64_t f = 0; f < s.frames; ++f) {
    const PlacedObject p = scripted_pose(mover, f);
    const double r = p.model.footprint_radius;
    if (std::fabs(p.table_x) + r > s.table.width_m / 2 ||
        std::fabs(p.table_y) + r > s.table.depth_m / 2) {
      return false;
    }
    for (std::size_t i = 1; i < s.objects.size(); ++i) {
      const PlacedObject& o = s.objects[i].start;
      const double need = r + o.model.footprint_radius + CLEARANCE_M;
      if (std::hypot(p.table_x - o.table_x, p.table_y - o.table_y) < need) { return false; }
    }
  }
  return true;
}

}  // namespace

PlacedObject scripted_pose(const ScriptedObject& object, std::uint64_t frame) noexcept {
  PlacedObject p = object.start;
  const double t = frame > object.appear_frame
                       ? static_cast<double>(frame - object.appear_frame) * FRAME_S
                       : 0.0;
  p.table_x += object.velocity_x * t;
  p.table_y += object.velocity_y * t;
  return p;
}

SequenceScript make_sequence_script(std::uint32_t objects, std::uint64_t frames,
                                    std::uint64_t seed) {
  SceneConfig config;
  config.objects = objects;
  const Scene scene = make_scene(config, seed);
  SequenceScript s{scene.table, {}, frames};
  for (const PlacedObject& o : scene.objects) { s.objects.push_back(ScriptedObject{o}); }
  core::Rng rng(~seed);
  if (!s.objects.empty()) {
    // Slide object 0 at 5-15 cm/s in a direction whose swept path stays clear; else it stands
    // still.
    ScriptedObject& mover = s.objects[0];
    for (int attempt = 0; attempt < PATH_ATTEMPTS; ++attempt) {
      const double speed = rng.uniform(0.05, 0.15), heading = rng.uniform(0.0, 2.0 * PI);
      mover.velocity_x = speed * std::cos(heading);
      mover.velocity_y = speed * std::sin(heading);
      if (path_is_clear(s, mover)) { break; }
      mover.velocity_x = mover.velocity_y = 0.0;
    }
  }
  if (s.objects.size() > 1) { s.objects[1].appear_frame = frames / 3; }
  if (s.objects.size() > 2) { s.objects[2].disappear_frame = 2 * frames / 3; }
  return s;
}

SyntheticSequence::SyntheticSequence(SequenceScript script, std::uint64_t seed,
                                     RenderOptions options)
    : script_(std::move(script)), options_(options), rng_(seed) {
  OF_ENFORCE(script_.objects.size() <= MAX_SCENE_OBJECTS,
             "SyntheticSequence: too many scripted objects");
  scene_.table = script_.table;
  scene_.objects.reserve(MAX_SCENE_OBJECTS);
}

bool SyntheticSequence::next(kernels::PointCloud& out) {
  if (frame_ >= script_.frames) { return false; }
  scene_.objects.clear();  // keeps its capacity: no allocation below
  for (std::size_t i = 0; i < script_.objects.size(); ++i) {
    const ScriptedObject& o = script_.objects[i];
    if (!o.present(frame_)) { continue; }
    scene_.objects.push_back(scripted_pose(o, frame_));
    scene_.objects.back().id = static_cast<std::uint32_t>(i);
  }
  render_scene(scene_, options_, rng_, out);
  const auto stamp = static_cast<std::int64_t>(frame_) * 1'000'000'000 / SEQUENCE_RATE_HZ;
  out.info.frame_id = frame_;
  out.info.sensor_stamp_ns = stamp;
  out.info.host_stamp_ns = stamp;
  ++frame_;
  return true;
}

}  // namespace orthoflow::simulation
