#include "graphs/nodes/session_script.hpp"

namespace orthoflow::graphs {

namespace {

simulation::ScriptedObject place(simulation::Category category, std::uint32_t instance,
                                 std::uint64_t seed, double x, double y, double yaw) {
  simulation::ScriptedObject o;
  o.start.model = simulation::make_object_model(category, instance, seed);
  o.start.table_x = x;
  o.start.table_y = y;
  o.start.yaw = yaw;
  return o;
}

}  // namespace

simulation::SequenceScript make_session_script(std::uint64_t frames, std::uint64_t seed) {
  using simulation::Category;
  simulation::SequenceScript s;
  s.frames = frames;
  const std::uint64_t end1 = frames * 2 / 5, start2 = frames * 9 / 20;
  // Table coordinates: x to the right, y away from the sensor, origin at the table centre (metres).
  auto mug = place(Category::MUG, 0, seed, -0.30, -0.12, 0.3);
  mug.disappear_frame = end1;
  mug.velocity_x = 0.05;  // slides 5 cm/s to the right: tracking must keep its id
  auto bottle = place(Category::BOTTLE, 0, seed, 0.05, -0.15, 0.0);
  bottle.disappear_frame = end1;
  auto bowl = place(Category::BOWL, 0, seed, 0.30, 0.12, 0.0);  // present all session long
  auto mug2 = place(Category::MUG, 1, seed, -0.12, 0.15, 2.0);
  mug2.appear_frame = start2;
  auto bottle2 = place(Category::BOTTLE, 1, seed, -0.30, 0.0, 1.0);
  bottle2.appear_frame = start2;
  auto plate = place(Category::PLATE, 0, seed, 0.08, 0.03, 0.0);  // never taught: must be Unknown
  plate.appear_frame = start2;
  s.objects = {mug, bottle, bowl, mug2, bottle2, plate};
  return s;
}

bool instructor_teaches(std::string_view category) noexcept { return category != "plate"; }

}  // namespace orthoflow::graphs
