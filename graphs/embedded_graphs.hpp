#pragma once
/// @file
/// @brief Graph files compiled into the library, so `orthoflow run` works without any file around.
#include <string_view>

namespace orthoflow::graphs {

/// @brief The text of graphs/tabletop.yaml as it was when the library was built.
[[nodiscard]] std::string_view embedded_tabletop_yaml() noexcept;

}  // namespace orthoflow::graphs
