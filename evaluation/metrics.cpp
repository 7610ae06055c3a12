#include "evaluation/metrics.hpp"

#include <cmath>

namespace orthoflow::evaluation {

void Confusion::add(std::uint32_t truth, std::optional<std::uint32_t> predicted) {
  counts[truth * (classes + 1) + (predicted ? *predicted : classes)] += 1;
}

void Confusion::merge(const Confusion& other) {
  for (std::size_t i = 0; i < counts.size() && i < other.counts.size(); ++i) {
    counts[i] += other.counts[i];
  }
}

std::size_t Confusion::total() const {
  std::size_t n = 0;
  for (const std::size_t c : counts) { n += c; }
  return n;
}

Scores score(const Confusion& c) {
  Scores s;
  s.answers = c.total();
  std::size_t correct = 0;
  double precision_sum = 0.0, recall_sum = 0.0;
  std::size_t asked_classes = 0;
  for (std::size_t k = 0; k < c.classes; ++k) {
    std::size_t row = 0, column = 0;
    for (std::size_t j = 0; j <= c.classes; ++j) { row += c.at(k, j); }
    for (std::size_t t = 0; t < c.classes; ++t) { column += c.at(t, k); }
    correct += c.at(k, k);
    s.unknown += c.at(k, c.classes);
    if (column > 0) {
      precision_sum += static_cast<double>(c.at(k, k)) / static_cast<double>(column);
    }
    if (row > 0) {
      recall_sum += static_cast<double>(c.at(k, k)) / static_cast<double>(row);
      ++asked_classes;
    }
  }
  if (s.answers == 0) { return s; }
  s.accuracy = static_cast<double>(correct) / static_cast<double>(s.answers);
  s.micro_recall = s.accuracy;
  const std::size_t named = s.answers - s.unknown;
  s.micro_precision = named == 0 ? 0.0 : static_cast<double>(correct) / static_cast<double>(named);
  s.macro_precision = c.classes == 0 ? 0.0 : precision_sum / static_cast<double>(c.classes);
  s.macro_recall = asked_classes == 0 ? 0.0 : recall_sum / static_cast<double>(asked_classes);
  return s;
}

MeanStd mean_std(const std::vector<double>& values) {
  MeanStd m;
  if (values.empty()) { return m; }
  double sum = 0.0;
  for (const double v : values) { sum += v; }
  m.mean = sum / static_cast<double>(values.size());
  if (values.size() < 2) { return m; }
  double sq = 0.0;
  for (const double v : values) { sq += (v - m.mean) * (v - m.mean); }
  m.std = std::sqrt(sq / static_cast<double>(values.size() - 1));
  return m;
}

}  // namespace orthoflow::evaluation
