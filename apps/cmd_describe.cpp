// `orthoflow describe FILE.pcd [--bins N] [--mode invariant|reference] [--threshold T] [--json]
// [--png OUT.png]`: the GOOD descriptor of one object cloud (kernels/good.hpp, docs/GOOD.md), with
// its object frame, bounding box, projection order and flags; --png draws the three projections
// side by side. `--dictionary FILE [--representation bow|lda|local-lda]`: its bag of words, its
// topics, or its word counts (what Local LDA learns from)
// instead (docs/SPIN_IMAGES.md).
#include <cairo.h>

#include <algorithm>
#include <array>
#include <charconv>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "apps/commands.hpp"
#include "apps/json_numbers.hpp"
#include "apps/spin_set_options.hpp"
#include "formats/pcd_io.hpp"
#include "kernels/descriptor_spec.hpp"
#include "kernels/good.hpp"
#include "learning/dictionary.hpp"

namespace orthoflow::apps {
namespace {

struct DescribeOptions {
  std::string file;
  std::size_t bins = 15;
  std::string mode = "invariant";
  std::optional<float> threshold;
  bool json = false;
  std::string png;
  std::string representation = "good";
  std::string dictionary;
  kernels::SpinSetParams spin{};  // --spin-*
};

struct Described {
  std::vector<float> descriptor;
  kernels::GoodResult result;
};

nlohmann::json flags_json(std::uint32_t flags) {
  static const std::array<std::pair<std::uint32_t, const char*>, 8> NAMES{{
      {kernels::FEW_POINTS, "few_points"},
      {kernels::COLLINEAR, "collinear"},
      {kernels::COPLANAR, "coplanar"},
      {kernels::AXES_AMBIGUOUS, "axes_ambiguous"},
      {kernels::SIGN_AMBIGUOUS, "sign_ambiguous"},
      {kernels::NAN_IGNORED, "nan_ignored"},
      {kernels::EMPTY_VIEW, "empty_view"},
      {kernels::FAR_POINTS_DROPPED, "far_points_dropped"},
  }};
  nlohmann::json out = nlohmann::json::array();
  for (const auto& [bit, name] : NAMES) {
    if ((flags & bit) != 0U) { out.push_back(name); }
  }
  return out;
}

nlohmann::json to_json(const DescribeOptions& o, const Described& d) {
  const kernels::GoodResult& r = d.result;
  nlohmann::json order = nlohmann::json::array();
  for (const kernels::GoodView v : r.order) { order.push_back(kernels::to_string(v)); }
  return {{"file", o.file},
          {"mode", o.mode},
          {"bins", o.bins},
          {"descriptor", floats_json(d.descriptor)},
          {"frame", floats_json(r.frame)},
          {"bbox", floats_json(r.bbox)},
          {"order", order},
          {"points_used", r.points_used},
          {"far_points", r.far_points},
          {"flags", flags_json(r.flags)},
          {"reliable", (r.flags & kernels::FRAME_UNRELIABLE) == 0U},
          {"side", floats_json(std::array<float, 1>{r.side})[0]},
          {"eigenvalues", floats_json(r.eigenvalues)}};
}

void print_text(const nlohmann::json& j) {
  std::cout << "file:        " << j["file"].get<std::string>()
            << "\nmode:        " << j["mode"].get<std::string>() << " (" << j["bins"] << " bins, "
            << j["descriptor"].size() << " values)\npoints used: " << j["points_used"]
            << " (far points left out: " << j["far_points"] << ")"
            << "\norder:       " << j["order"].dump() << "\nbbox:        " << j["bbox"].dump()
            << "\nflags:       " << j["flags"].dump() << "\nframe:       " << j["frame"].dump()
            << "\ndescriptor:  " << j["descriptor"].dump() << '\n';
}

// --- PNG: one panel per projection in descriptor order; cell darkness = value / block maximum. ---

constexpr double PANEL = 320.0;
constexpr double GAP = 24.0;
constexpr double TITLE = 28.0;

struct AxisStyle {
  const char* name;
  double r, g, b;
};
constexpr std::array<AxisStyle, 3> AXES{
    {{"X", 0.85, 0.1, 0.1}, {"Y", 0.1, 0.6, 0.1}, {"Z", 0.1, 0.2, 0.9}}};

// Row and column axis of each canonical view (GOOD_REFERENCE.md section 5).
constexpr std::array<std::array<std::size_t, 2>, 3> VIEW_AXES{{{1, 2}, {0, 2}, {0, 1}}};

void draw_arrow(cairo_t* cr, double x0, double y0, double dx, double dy, const AxisStyle& s) {
  cairo_set_source_rgb(cr, s.r, s.g, s.b);
  cairo_set_line_width(cr, 3.0);
  cairo_move_to(cr, x0, y0);
  cairo_line_to(cr, x0 + dx, y0 + dy);
  cairo_stroke(cr);
  cairo_move_to(cr, x0 + dx * 1.12 - 5.0, y0 + dy * 1.12 + 5.0);
  cairo_show_text(cr, s.name);
}

void draw_panel(cairo_t* cr, double left, std::span<const float> block, std::size_t n,
                kernels::GoodView view, std::size_t rank) {
  const float peak = std::max(*std::max_element(block.begin(), block.end()), 1e-12F);
  const double cell = PANEL / static_cast<double>(n);
  for (std::size_t row = 0; row < n; ++row) {
    for (std::size_t col = 0; col < n; ++col) {
      const double shade = 1.0 - static_cast<double>(block[row * n + col] / peak);
      cairo_set_source_rgb(cr, shade, shade, shade);
      // Column to the right, row upwards, so each view is drawn as seen with its two axes.
      cairo_rectangle(cr, left + static_cast<double>(col) * cell,
                      TITLE + PANEL - static_cast<double>(row + 1) * cell, cell, cell);
      cairo_fill(cr);
    }
  }
  cairo_set_source_rgb(cr, 0.5, 0.5, 0.5);
  cairo_set_line_width(cr, 1.0);
  cairo_rectangle(cr, left, TITLE, PANEL, PANEL);
  cairo_stroke(cr);
  const std::size_t v = static_cast<std::size_t>(view);
  const double cx = left + PANEL / 2.0;
  const double cy = TITLE + PANEL / 2.0;  // the square is centred on the centroid, the frame origin
  draw_arrow(cr, cx, cy, 0.0, -PANEL * 0.3, AXES[VIEW_AXES[v][0]]);
  draw_arrow(cr, cx, cy, PANEL * 0.3, 0.0, AXES[VIEW_AXES[v][1]]);
  cairo_set_source_rgb(cr, 0.0, 0.0, 0.0);
  cairo_move_to(cr, left, TITLE - 8.0);
  const std::string title = std::to_string(rank + 1) + ". " + kernels::to_string(view);
  cairo_show_text(cr, title.c_str());
}

bool write_png(const std::string& path, const Described& d, std::size_t n) {
  const int width = static_cast<int>(3.0 * PANEL + 4.0 * GAP);
  const int height = static_cast<int>(PANEL + TITLE + GAP);
  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, width, height), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> cr(cairo_create(surface.get()), cairo_destroy);
  cairo_set_source_rgb(cr.get(), 1.0, 1.0, 1.0);
  cairo_paint(cr.get());
  cairo_select_font_face(cr.get(), "sans-serif", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_BOLD);
  cairo_set_font_size(cr.get(), 16.0);
  const std::size_t nn = n * n;
  for (std::size_t k = 0; k < 3; ++k) {
    draw_panel(cr.get(), GAP + static_cast<double>(k) * (PANEL + GAP),
               std::span<const float>(d.descriptor).subspan(k * nn, nn), n, d.result.order[k], k);
  }
  cairo_surface_flush(surface.get());
  return cairo_surface_write_to_png(surface.get(), path.c_str()) == CAIRO_STATUS_SUCCESS;
}

[[noreturn]] void fail(const std::string& message, int code) {
  std::cerr << "orthoflow describe: " << message << '\n';
  throw CLI::RuntimeError(code);
}

// The bag of words or topics of one view (docs/SPIN_IMAGES.md): the Describer under that
// specification, as the graph, the memory and the evaluation describe it.
void run_describe_local(const DescribeOptions& o, const kernels::PointCloud& cloud) {
  const auto kind =
      kernels::descriptor_kind(o.representation).value_or(kernels::DescriptorKind::BOW);
  kernels::DescriptorSpec spec = kernels::DescriptorSpec::make_spin_set(o.spin);
  if (kind != kernels::DescriptorKind::SPIN_SET) {
    auto words = learning::load_dictionary(o.dictionary);
    if (!words) fail(words.error(), EXIT_BAD_INPUT);
    auto dictionary = std::make_shared<const kernels::VisualDictionary>(std::move(words.value()));
    // --dictionary without --representation: the bag of words.
    spec = kernels::DescriptorSpec::over_dictionary(
        kind == kernels::DescriptorKind::GOOD ? kernels::DescriptorKind::BOW : kind, dictionary);
  }
  if (auto valid = spec.validate(); !valid) fail(valid.error(), EXIT_USAGE);
  kernels::Describer describer(spec);
  std::vector<float> values(spec.length());
  auto described = describer.describe(cloud.points(), values);
  if (!described) fail(o.file + ": " + kernels::to_string(described.error()), EXIT_BAD_INPUT);
  const nlohmann::json j{{"file", o.file},
                         {"representation", std::string(kernels::to_string(spec.kind))},
                         {"specification", spec.describe()},
                         {"spin_images", describer.features()},
                         {"descriptor", floats_json(values)},
                         {"frame", floats_json(described->frame)},
                         {"bbox", floats_json(described->bbox)}};
  if (o.json) {
    std::cout << j.dump() << '\n';
    return;
  }
  std::cout << "file:        " << o.file << "\nspec:        " << spec.describe()
            << "\nspin images: " << describer.features() << "\nbbox:        " << j["bbox"].dump()
            << "\ndescriptor:  " << j["descriptor"].dump() << '\n';
}

void run_describe(const DescribeOptions& o) {
  auto cloud_result = formats::read_pcd(o.file);
  if (!cloud_result) { fail(cloud_result.error().to_string(), EXIT_BAD_INPUT); }
  if (o.representation != "good" || !o.dictionary.empty()) {
    if (o.dictionary.empty() && o.representation != "spin")
      fail("--representation bow, lda or local-lda needs --dictionary FILE", EXIT_USAGE);
    if (!o.png.empty()) fail("--png draws GOOD's projections only", EXIT_USAGE);
    run_describe_local(o, *cloud_result);
    return;
  }
  // This command shows GOOD's own details (projections, order, entropies), so it calls compute_good
  // directly; the length still comes from the one specification.
  kernels::DescriptorSpec spec = kernels::DescriptorSpec::make_good(
      o.bins, o.mode == "reference" ? kernels::GoodMode::REFERENCE : kernels::GoodMode::INVARIANT);
  spec.good.threshold = o.threshold;
  kernels::GoodScratch scratch(std::max<std::size_t>(o.bins, 1));
  Described d;
  d.descriptor.assign(spec.length(), 0.0F);
  auto good_result =
      kernels::compute_good(cloud_result->points(), spec.good, scratch, d.descriptor);
  if (!good_result) {
    const bool bad_input = good_result.error() == kernels::GoodError::EMPTY_CLOUD ||
                           good_result.error() == kernels::GoodError::NO_FINITE_POINTS;
    fail(o.file + ": " + kernels::to_string(good_result.error()),
         bad_input ? EXIT_BAD_INPUT : EXIT_FAILURE_GENERIC);
  }
  d.result = *good_result;
  const nlohmann::json j = to_json(o, d);
  if (o.json) {
    std::cout << j.dump() << '\n';
  } else {
    print_text(j);
  }
  if (!o.png.empty() && !write_png(o.png, d, o.bins)) {
    fail("cannot write " + o.png, EXIT_FAILURE_GENERIC);
  }
}

}  // namespace

void add_describe_command(CLI::App& app) {
  auto* cmd = app.add_subcommand(
      "describe", "GOOD descriptor, object frame and projections of an object cloud");
  auto o = std::make_shared<DescribeOptions>();
  cmd->add_option("file", o->file, "object PCD file")->required();
  cmd->add_option("--bins", o->bins, "bins per projection side (15 thesis default, 5 compact)")
      ->check(CLI::Range(std::size_t{1}, kernels::GOOD_MAX_BINS));
  cmd->add_option("--mode", o->mode,
                  "invariant (pose-invariant frame) or reference (reproduces the reference code)")
      ->check(CLI::IsMember({"invariant", "reference"}));
  cmd->add_option("--threshold", o->threshold,
                  "sign threshold t in metres (default 0.015 invariant, 0.0015 reference)")
      ->check(CLI::Range(0.0F, 1e3F));
  cmd->add_flag("--json", o->json,
                "print one JSON object: descriptor, frame, bbox, order, points_used, flags");
  cmd->add_option("--png", o->png,
                  "draw the three projections with the frame axes into this PNG file");
  cmd->add_option(
         "--representation", o->representation,
         "good, spin (the set of its spin images), bow (the view's words), lda (its "
         "topics) or local-lda (its word counts); bow, lda and local-lda need --dictionary")
      ->check(CLI::IsMember({"good", "spin", "bow", "lda", "local-lda"}));
  add_spin_set_options(cmd, o->spin);
  cmd->add_option("--dictionary", o->dictionary,
                  "the visual words (`orthoflow dictionary build`); implies bow unless lda");
  cmd->callback([o] { run_describe(*o); });
}

}  // namespace orthoflow::apps
