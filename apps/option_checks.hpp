#pragma once
/// @file
/// @brief One rule for every numeric option of every command (issue 16: `--ct nan` aborted,
/// `ipc echo --timeout-ms -5` never returned): a value must be a finite, non-negative number. CLI11
/// already refuses trailing garbage ("5abc") when it converts; NaN, infinities and negative numbers
/// it accepts, so check_numeric_options() adds the rule to every INT, UINT and FLOAT option once
/// all commands are declared. An INT or UINT option (counts such as --frames) must also be a whole
/// number within int64: "1.5" and "99999999999999999999" are refused with what is wrong. Commands
/// add their own ranges on top.
#include <CLI/CLI.hpp>

namespace orthoflow::apps {

/// @brief Adds the finite, non-negative rule to every numeric option of @p app and its subcommands,
/// recursively. Call once, after every command is added.
void check_numeric_options(CLI::App& app);

/// @brief For an option that names a category: composes what a person typed into Unicode NFC
/// (core::normalized_label), so a decomposed "café" is the same category as the composed one. Text
/// that is no label at all passes unchanged, and the command's own check says what is wrong.
[[nodiscard]] CLI::Validator composed_label();

}  // namespace orthoflow::apps
