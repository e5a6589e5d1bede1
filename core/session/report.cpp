#include "core/session/report.h"

#include <cmath>
#include <cstdio>

namespace flexarm {

void thinSeries(std::vector<double>& x, std::vector<double>& y, std::size_t n) {
  if (x.size() <= n || n == 0) return;
  const std::size_t step = (x.size() + n - 1) / n;
  std::size_t k = 0;
  for (std::size_t i = 0; i < x.size(); i += step, ++k) {
    x[k] = x[i];
    y[k] = y[i];
  }
  x.resize(k);
  y.resize(k);
}

std::string formatFixed(double v, int decimals) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

std::string formatSignificant(double v, int digits) {
  if (!std::isfinite(v)) return "n/a";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*g", digits, v);
  return buf;
}

nlohmann::json Report::toJson() const {
  nlohmann::json logsJson = nlohmann::json::array();
  for (const auto& l : logs)
    logsJson.push_back({{"name", l.name}, {"path", l.path}, {"sha256", l.sha256}, {"note", l.note}});
  nlohmann::json sectionsJson = nlohmann::json::array();
  for (const auto& s : sections) sectionsJson.push_back({{"title", s.title}, {"values", s.values}});
  return {{"title", title},       {"flexarm_version", flexarmVersion},
          {"session", session},   {"logs", logsJson},
          {"warnings", warnings}, {"sections", sectionsJson}};
}

}  // namespace flexarm
