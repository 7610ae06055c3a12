#include "evaluation/eval_error.hpp"

namespace orthoflow::evaluation {

const char* to_string(EvalError::Code code) noexcept {
  switch (code) {
    case EvalError::Code::BAD_DATASET:
      return "bad_dataset";
    case EvalError::Code::BAD_VIEW:
      return "bad_view";
    case EvalError::Code::BAD_CONFIG:
      return "bad_config";
    case EvalError::Code::TOO_FEW_VIEWS:
      return "too_few_views";
    case EvalError::Code::TOO_FEW_CATEGORIES:
      return "too_few_categories";
    case EvalError::Code::WRITE_FAILED:
      return "write_failed";
  }
  return "unknown";
}

std::string EvalError::to_string() const {
  return std::string(evaluation::to_string(code)) + ": " + message;
}

}  // namespace orthoflow::evaluation
