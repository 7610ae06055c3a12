#include "evaluation/dataset.hpp"

#include <algorithm>
#include <system_error>

#include "learning/learner.hpp"

namespace orthoflow::evaluation {
namespace {

namespace fs = std::filesystem;

EvalError bad(std::string message) {
  return EvalError{EvalError::Code::BAD_DATASET, std::move(message)};
}

bool hidden(const fs::path& p) { return p.filename().string().starts_with('.'); }
bool is_pcd(const fs::path& p) { return p.extension() == ".pcd"; }

/// The entries of @p dir sorted by name (directory_iterator order is unspecified).
Result<std::vector<fs::directory_entry>, EvalError> sorted_entries(const fs::path& dir) {
  std::error_code ec;
  fs::directory_iterator it(dir, ec);
  if (ec) { return err(bad("cannot list " + dir.string() + ": " + ec.message())); }
  std::vector<fs::directory_entry> out;
  for (const fs::directory_entry& e : it) {
    if (!hidden(e.path())) { out.push_back(e); }
  }
  std::sort(out.begin(), out.end(),
            [](const auto& a, const auto& b) { return a.path().filename() < b.path().filename(); });
  return out;
}

bool is_dir(const fs::directory_entry& e) {
  std::error_code ec;
  return e.is_directory(ec);
}

/// Adds the views of one instance folder.
Result<void, EvalError> scan_instance(Dataset& ds, const fs::directory_entry& inst,
                                      std::uint32_t category) {
  auto files = sorted_entries(inst.path());
  if (!files) { return err(files.error()); }
  const std::string prefix = ds.categories[category] + "/" + inst.path().filename().string();
  const auto instance = static_cast<std::uint32_t>(ds.instances.size());
  bool any = false;
  for (const fs::directory_entry& f : *files) {
    if (is_dir(f) || !is_pcd(f.path())) { continue; }
    ds.views.push_back(
        DatasetView{category, instance, prefix + "/" + f.path().filename().string()});
    any = true;
  }
  if (any) { ds.instances.push_back(prefix); }
  return {};
}

Result<void, EvalError> scan_category(Dataset& ds, const fs::directory_entry& cat) {
  const std::string name = cat.path().filename().string();
  if (name.size() > learning::LABEL_MAX_BYTES) {
    return err(bad("category name '" + name + "' is longer than " +
                   std::to_string(learning::LABEL_MAX_BYTES) + " bytes"));
  }
  auto entries = sorted_entries(cat.path());
  if (!entries) { return err(entries.error()); }
  const auto category = static_cast<std::uint32_t>(ds.categories.size());
  ds.categories.push_back(name);
  const std::size_t before = ds.views.size();
  for (const fs::directory_entry& e : *entries) {
    if (is_dir(e)) {
      if (auto r = scan_instance(ds, e, category); !r) { return r; }
    } else if (is_pcd(e.path())) {
      return err(
          bad(e.path().string() +
              " is directly in a category folder: expected DIR/<category>/<instance>/<view>.pcd"));
    }
  }
  if (ds.views.size() == before) {
    return err(bad("category '" + name + "' (" + cat.path().string() + ") has no .pcd view"));
  }
  return {};
}

}  // namespace

std::vector<std::size_t> Dataset::views_of(std::uint32_t category) const {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (views[i].category == category) { out.push_back(i); }
  }
  return out;
}

Result<Dataset, EvalError> scan_dataset(const std::filesystem::path& root) {
  std::error_code ec;
  if (!fs::is_directory(root, ec)) { return err(bad(root.string() + " is not a directory")); }
  auto entries = sorted_entries(root);
  if (!entries) { return err(entries.error()); }
  Dataset ds;
  ds.root = root;
  for (const fs::directory_entry& e : *entries) {
    if (is_dir(e)) {
      if (auto r = scan_category(ds, e); !r) { return err(r.error()); }
    } else if (is_pcd(e.path())) {
      return err(bad(e.path().string() +
                     " is at the top level: expected DIR/<category>/<instance>/<view>.pcd"));
    }
  }
  if (ds.views.empty()) {
    return err(
        bad(root.string() + " holds no view (expected DIR/<category>/<instance>/<view>.pcd)"));
  }
  return ds;
}

}  // namespace orthoflow::evaluation
