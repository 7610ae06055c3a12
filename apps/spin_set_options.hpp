#pragma once
/// @file
/// @brief The options of a spin-image set (`--representation spin`), one declaration for every
/// command that describes with one (describe, evaluate).
#include <CLI/CLI.hpp>

#include "kernels/spin_set.hpp"

namespace orthoflow::apps {

/// @brief --spin-keypoints, --spin-width, --spin-support and --spin-leaf, written to @p spin (which
/// must outlive the command's callback).
void add_spin_set_options(CLI::App* cmd, kernels::SpinSetParams& spin);

}  // namespace orthoflow::apps
