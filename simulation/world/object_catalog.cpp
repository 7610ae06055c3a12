// Shape recipes per category. Dimensions (metres) follow real restaurant objects; each instance
// draws its own proportions so that instances of a category differ while categories stay apart.
#include "simulation/world/object_catalog.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string_view>

#include "simulation/world/object_catalog_parts.hpp"

namespace orthoflow::simulation {
namespace {

constexpr std::array<std::string_view, CATEGORY_COUNT> NAMES = {
    "bottle", "bowl",       "flask", "fork",   "knife",      "mug",  "plate",  "spoon", "teapot",
    "vase",   "box",        "can",   "glass",  "wine_glass", "jug",  "pot",    "pan",   "ball",
    "book",   "cereal_box", "jar",   "funnel", "bucket",     "tray", "remote", "candle"};
constexpr std::array<std::uint32_t, CATEGORY_COUNT> COLOURS = {
    0x2E8B57, 0xF5DEB3, 0x87CEEB, 0xC0C0C0, 0xA9A9A9, 0xB22222, 0xFFFAF0, 0xD3D3D3, 0x8B4513,
    0x6A5ACD, 0xDAA520, 0xDC143C, 0xE0FFFF, 0xF0E68C, 0xCD853F, 0x708090, 0x2F4F4F, 0xFF8C00,
    0x4169E1, 0xFFD700, 0xBDB76B, 0x9ACD32, 0x4682B4, 0x8FBC8F, 0x1C1C1C, 0xFFF8DC};

void cutlery(ObjectBuilder& b, core::Rng& r, Category c) {
  const double len = r.uniform(0.17, 0.22), t = r.uniform(0.010, 0.014);
  b.box({-0.03, 0, t / 2}, {len / 2 - 0.03, 0.008, t / 2});  // handle
  const double head_x = len / 2 - 0.02;
  if (c == Category::FORK) {
    for (double y : {-0.009, -0.003, 0.003, 0.009}) {
      b.box({head_x + 0.012, y, t / 2}, {0.025, 0.0018, t / 2});
    }
  } else if (c == Category::KNIFE) {
    b.box({head_x, 0, t / 3}, {0.05, 0.012, t / 3});
  } else {
    b.ellipsoid({head_x + 0.01, 0, t / 2}, {0.03, r.uniform(0.016, 0.022), t / 2 + 0.002},
                0.0);  // cut at the table
  }
}

/// Turned shapes: stacks of frusta (bottle, flask, vase, can).
void turned(ObjectBuilder& b, core::Rng& r, Category c) {
  if (c == Category::BOTTLE) {
    const double rad = r.uniform(0.03, 0.045), h = r.uniform(0.12, 0.2),
                 neck = r.uniform(0.012, 0.018);
    const double sh = r.uniform(0.03, 0.05);
    b.frustum(0, rad, rad, h);
    b.frustum(h, rad, neck, sh);
    b.frustum(h + sh, neck, neck, r.uniform(0.04, 0.07));
  } else if (c == Category::FLASK) {
    const double rb = r.uniform(0.05, 0.07), rt = r.uniform(0.015, 0.02), h = r.uniform(0.1, 0.14);
    b.frustum(0, rb, rt, h);
    b.frustum(h, rt, rt, r.uniform(0.04, 0.06));
  } else if (c == Category::VASE) {
    const double rb = r.uniform(0.035, 0.05), rm = r.uniform(0.055, 0.08),
                 rn = r.uniform(0.02, 0.03);
    const double h1 = r.uniform(0.08, 0.14), h2 = r.uniform(0.06, 0.1);
    b.frustum(0, rb, rm, h1);
    b.frustum(h1, rm, rn, h2);
    b.frustum(h1 + h2, rn, rn * 1.3, r.uniform(0.03, 0.06), true);
  } else {  // can: a standard 330 ml can varies little
    const double rad = r.uniform(0.032, 0.034);
    b.frustum(0, rad, rad, r.uniform(0.1, 0.123));
  }
}

/// Tableware with an opening or a handle (bowl, mug, plate, teapot).
void tableware(ObjectBuilder& b, core::Rng& r, Category c) {
  if (c == Category::BOWL) {
    const double rad = r.uniform(0.06, 0.1), depth = rad * r.uniform(0.5, 0.7);
    b.ellipsoid({0, 0, depth}, {rad, rad, depth}, 0.0, depth);
  } else if (c == Category::MUG) {
    const double rad = r.uniform(0.035, 0.05), h = r.uniform(0.08, 0.11);
    b.frustum(0, rad, rad, h, true);
    b.arc({rad, 0, h / 2}, h * r.uniform(0.25, 0.32), 0.008, 0.0, M_PI, 7);
  } else if (c == Category::PLATE) {
    const double rad = r.uniform(0.1, 0.14);
    b.frustum(0, rad * 0.7, rad, r.uniform(0.015, 0.022));
  } else {  // teapot: body, lid, spout and handle
    const double a = r.uniform(0.07, 0.09), hz = r.uniform(0.05, 0.07);
    b.ellipsoid({0, 0, hz}, {a, a, hz});
    b.ellipsoid({0, 0, 2 * hz}, {a * 0.4, a * 0.4, 0.015});
    b.arc({a * 0.85, 0, hz * 0.9}, hz * 0.9, 0.01, 0.6, 1.6, 5);
    b.arc({-a, 0, hz}, hz * 0.6, 0.008, -M_PI, 0.0, 7);
  }
}

void build(ObjectBuilder& b, core::Rng& r, Category c) {
  switch (c) {
    case Category::BOTTLE:
    case Category::FLASK:
    case Category::VASE:
    case Category::CAN:
      turned(b, r, c);
      break;
    case Category::BOWL:
    case Category::MUG:
    case Category::PLATE:
    case Category::TEAPOT:
      tableware(b, r, c);
      break;
    case Category::FORK:
    case Category::KNIFE:
    case Category::SPOON:
      cutlery(b, r, c);
      break;
    case Category::BOX: {
      const double hx = r.uniform(0.04, 0.1), hy = r.uniform(0.03, 0.08),
                   hz = r.uniform(0.025, 0.1);
      b.box({0, 0, hz}, {hx, hy, hz});
      break;
    }
    case Category::GLASS:
    case Category::WINE_GLASS:
    case Category::JUG:
    case Category::POT:
    case Category::PAN:
    case Category::BALL:
    case Category::BOOK:
    case Category::CEREAL_BOX:
    case Category::JAR:
    case Category::FUNNEL:
    case Category::BUCKET:
    case Category::TRAY:
    case Category::REMOTE:
    case Category::CANDLE:
      build_household(b, r, c);
      break;
  }
}

/// Footprint radius and height from the parts' extents.
void measure(ObjectModel& m) {
  for (std::size_t i = 0; i < m.part_count; ++i) {
    const Primitive& p = m.parts[i];
    double reach = 0, top = 0;
    if (p.kind == PrimitiveKind::FRUSTUM) {
      reach = std::max(p.size[0], p.size[1]);
      top = p.center[2] + p.size[2];
    } else if (p.kind == PrimitiveKind::BOX) {
      reach = std::hypot(std::fabs(p.center[0]) + p.size[0], std::fabs(p.center[1]) + p.size[1]);
      top = p.center[2] + p.size[2];
    } else {
      reach = std::hypot(p.center[0], p.center[1]) + std::max(p.size[0], p.size[1]);
      top = std::min(p.center[2] + p.size[2], p.clip_max);
    }
    m.footprint_radius = std::max(m.footprint_radius, reach);
    m.height = std::max(m.height, top);
  }
}

}  // namespace

const char* category_name(Category c) noexcept { return NAMES[static_cast<std::size_t>(c)].data(); }

std::optional<Category> category_from_name(std::string_view name) noexcept {
  for (std::size_t i = 0; i < CATEGORY_COUNT; ++i) {
    if (NAMES[i] == name) { return static_cast<Category>(i); }
  }
  return std::nullopt;
}

ObjectModel make_object_model(Category category, std::uint32_t instance,
                              std::uint64_t shape_seed) noexcept {
  ObjectModel m;
  m.category = category;
  m.instance = instance;
  core::Rng r(0x0B1EC7ULL * 1000003ULL + static_cast<std::uint64_t>(category) * 65537ULL +
              instance + shape_seed * 0x9E3779B97F4A7C15ULL);
  ObjectBuilder b{m};
  build(b, r, category);
  measure(m);
  // Instances vary in shade around the category colour.
  const std::uint32_t base = COLOURS[static_cast<std::size_t>(category)];
  const auto shade = static_cast<std::uint32_t>(r.below(48));
  auto ch = [&](int s) {
    return std::min<std::uint32_t>(255U, ((base >> s) & 0xFFU) * 3 / 4 + shade);
  };
  m.rgb = 0xFF000000U | (ch(16) << 16) | (ch(8) << 8) | ch(0);
  return m;
}

}  // namespace orthoflow::simulation
