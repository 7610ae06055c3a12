// Fuzzes the web view's request decoding (ui/api_request.hpp) and access checks
// (ui/access_policy.hpp) with arbitrary requests. The input is read as
//   METHOD SP PATH[?QUERY] LF (NAME ":" VALUE LF)* LF BODY
// (a missing part is empty), so the fuzzer reaches every route, header and body. No input may
// crash, hang, leak or hit UB; a refused request must carry a 4xx status of the documented set and
// a message; an accepted one must hold what its kind promises (a track id >= 1, a label that passes
// the label rule, a positive finite rate, an asset path that is the request's own).
#include <cmath>
#include <cstdint>
#include <string_view>
#include <vector>

#include "core/label_text.hpp"
#include "ui/access_policy.hpp"
#include "ui/api_request.hpp"

namespace ui = orthoflow::ui;

namespace {

std::string_view next_line(std::string_view& rest) {
  const std::size_t end = rest.find('\n');
  const std::string_view line = rest.substr(0, end);
  rest = end == std::string_view::npos ? std::string_view{} : rest.substr(end + 1);
  return line;
}

void check_decoded(const ui::RawRequest& raw) {
  using Kind = ui::ApiRequest::Kind;
  const auto decoded = ui::decode_request(raw);
  if (!decoded) {
    const int s = decoded.error().status;
    if ((s != 400 && s != 404 && s != 405 && s != 413 && s != 415) ||
        decoded.error().message.empty())
      __builtin_trap();
    return;
  }
  const ui::ApiRequest& r = *decoded;
  const bool has_track = r.kind == Kind::TEACH || r.kind == Kind::CORRECT || r.kind == Kind::ASK;
  const bool has_label = r.kind == Kind::TEACH || r.kind == Kind::CORRECT || r.kind == Kind::FORGET;
  if (has_track && r.track == 0) __builtin_trap();
  if (has_label &&
      orthoflow::core::check_label(r.label.view()) != orthoflow::core::LabelProblem::NONE)
    __builtin_trap();
  if (r.kind == Kind::EVENTS && !(std::isfinite(r.hz) && r.hz > 0.0)) __builtin_trap();
  if (r.kind == Kind::ASSET && (r.asset != raw.path || raw.method != "GET")) __builtin_trap();
  if (raw.body.size() > ui::MAX_BODY_BYTES) __builtin_trap();
}

void check_guarded(const ui::RawRequest& raw) {
  static const ui::AccessPolicy loopback = ui::make_access_policy("127.0.0.1", 8080, "");
  static const ui::AccessPolicy lan =
      ui::make_access_policy("192.0.2.1", 8080, "0123456789abcdef0123456789abcdef");
  static const ui::AccessPolicy any =
      ui::make_access_policy("0.0.0.0", 8080, "0123456789abcdef0123456789abcdef");
  for (const ui::AccessPolicy* p : {&loopback, &lan, &any}) {
    const auto denied = ui::check_access(*p, raw);
    if (denied && ((denied->status != 401 && denied->status != 403) || denied->message.empty()))
      __builtin_trap();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string_view rest(reinterpret_cast<const char*>(data), size);
  const std::string_view start = next_line(rest);
  const std::size_t space = start.find(' ');
  ui::RawRequest raw;
  raw.method = start.substr(0, space);
  std::string_view target = space == std::string_view::npos ? "" : start.substr(space + 1);
  const std::size_t question = target.find('?');
  raw.path = target.substr(0, question);
  raw.query = question == std::string_view::npos ? "" : target.substr(question + 1);
  std::vector<ui::HttpHeader> headers;
  for (std::string_view line = next_line(rest); !line.empty(); line = next_line(rest)) {
    const std::size_t colon = line.find(':');
    std::string_view value = colon == std::string_view::npos ? "" : line.substr(colon + 1);
    while (!value.empty() && value.front() == ' ') value.remove_prefix(1);
    headers.push_back({line.substr(0, colon), value});
  }
  raw.headers = headers;
  raw.body = rest;
  check_decoded(raw);
  check_guarded(raw);
  return 0;
}
