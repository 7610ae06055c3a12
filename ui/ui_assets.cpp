#include "ui/ui_assets.hpp"

namespace orthoflow::ui {

const Asset* find_asset(std::string_view path) noexcept {
  // Exact match only: "/../x", "/app.js/", "//app.js" or "/APP.JS" name nothing.
  for (const Asset& asset : embedded_assets()) {
    if (path == asset.path) return &asset;
  }
  return nullptr;
}

}  // namespace orthoflow::ui
