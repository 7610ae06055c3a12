#pragma once
/// @file
/// @brief The error of every evaluation step: a code and a sentence naming the file or setting at
/// fault.
#include <cstdint>
#include <string>

namespace orthoflow::evaluation {

/// @brief Why an evaluation step failed. Nothing partial is reported as a result when one is
/// returned.
struct EvalError {
  enum class Code : std::uint8_t {
    BAD_DATASET,         ///< the directory is missing, empty or not laid out as
                         ///< DIR/<category>/<instance>/<view>.pcd
    BAD_VIEW,            ///< a view file could not be read or gives no descriptor
    BAD_CONFIG,          ///< a protocol setting is out of range (folds, runs, bins, levels, ...)
    TOO_FEW_VIEWS,       ///< the protocol needs more views per category than the dataset has
    TOO_FEW_CATEGORIES,  ///< the protocol needs more categories than the dataset has (teacher: 2,
                         ///< teacher-context: 3)
    WRITE_FAILED,        ///< results, plots or the cache could not be written
  };
  Code code = Code::BAD_CONFIG;
  std::string message;
  /// @brief "<code name>: <message>".
  [[nodiscard]] std::string to_string() const;
};

/// @brief Lower-case name of @p code ("bad_dataset", ...).
[[nodiscard]] const char* to_string(EvalError::Code code) noexcept;

}  // namespace orthoflow::evaluation
