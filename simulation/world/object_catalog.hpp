#pragma once
/// @file
/// @brief The synthetic object categories (the thesis's restaurant set plus boxes and cans, then
/// household objects for the object-view evaluation) and their parametric instances, built from the
/// solids in shape_primitives.hpp.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string_view>

#include "simulation/world/shape_primitives.hpp"

namespace orthoflow::simulation {

/// @brief Object categories. Ids are stable: new categories are only ever appended.
enum class Category : std::uint8_t {
  // The tabletop scene set (SCENE_CATEGORY_COUNT): the thesis's restaurant objects, boxes and cans.
  BOTTLE,
  BOWL,
  FLASK,
  FORK,
  KNIFE,
  MUG,
  PLATE,
  SPOON,
  TEAPOT,
  VASE,
  BOX,
  CAN,
  // Household objects added for the object-view dataset (issue 8: at least 20 categories).
  GLASS,
  WINE_GLASS,
  JUG,
  POT,
  PAN,
  BALL,
  BOOK,
  CEREAL_BOX,
  JAR,
  FUNNEL,
  BUCKET,
  TRAY,
  REMOTE,
  CANDLE
};
/// @brief Every category: the object-view dataset's default and the names category_from_name knows.
inline constexpr std::size_t CATEGORY_COUNT = 26;
/// @brief The first categories, which random tabletop scenes draw from when none are given. Fixed
/// at the original twelve so that seeded scenes (golden files, sessions, `orthoflow synth`) keep
/// their bytes as the catalog grows.
inline constexpr std::size_t SCENE_CATEGORY_COUNT = 12;
static_assert(SCENE_CATEGORY_COUNT <= CATEGORY_COUNT);

/// @brief Lower-case name ("bottle", ..., "wine_glass"). @pre @p c is a Category enumerator.
[[nodiscard]] const char* category_name(Category c) noexcept;
/// @brief The category with that name, if any.
[[nodiscard]] std::optional<Category> category_from_name(std::string_view name) noexcept;

inline constexpr std::size_t MAX_PRIMITIVES = 16;

/// @brief One object instance in its own frame: z up (the table normal), origin on the table.
struct ObjectModel {
  Category category = Category::BOX;
  std::uint32_t instance = 0;
  std::array<Primitive, MAX_PRIMITIVES> parts{};
  std::size_t part_count = 0;
  double footprint_radius = 0.0;  ///< radius of a circle around the origin that holds the footprint
  double height = 0.0;            ///< top of the highest part above the table
  std::uint32_t rgb = 0xFFFFFFFFU;
};

/// @brief The model of instance @p instance of @p category: shape parameters drawn from a generator
/// seeded by (category, instance, @p shape_seed), so the same triple is the same object in every
/// scene and dataset; another shape_seed gives a fresh set of instances (e.g. a held-out test set).
[[nodiscard]] ObjectModel make_object_model(Category category, std::uint32_t instance,
                                            std::uint64_t shape_seed = 0) noexcept;

}  // namespace orthoflow::simulation
