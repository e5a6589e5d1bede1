// flexarm info LOG [--json]: what a log holds.
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>

#include "app/cli/cli.h"
#include "app/cli/log_args.h"
#include "core/io/ranges.h"

namespace flexarm::cli {
namespace {

OptionTable infoTable() {
  OptionTable t("flexarm info LOG [options] [--json]",
                "Prints the channels (name, unit, role, min, max, mean), sample rate, length, metadata and the "
                "estimation and validation ranges of LOG.");
  t.add(flagOption("json", "print JSON instead of text")).group("Reading the log").add(logReadOptionList());
  return t;
}

nlohmann::json rangeJson(const IdData& d, const std::optional<SampleRange>& r) {
  if (!r) return nullptr;
  return {{"begin_sample", r->begin},
          {"end_sample", r->end},
          {"samples", r->size()},
          {"start_s", d.timeAt(r->begin)},
          {"end_s", d.timeAt(r->end > 0 ? r->end - 1 : 0)}};
}

}  // namespace

int runInfo(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(infoTable());
  if (auto rc = parseArguments(args, argv, "info", out, err)) return *rc;
  if (args.positional().size() != 1) {
    err << "flexarm info: expected exactly one LOG\n" << args.table().help();
    return kExitUsage;
  }
  auto options = logReadOptions(args, err);
  if (!options) return kExitUsage;
  const std::string path = args.positional()[0];
  auto data = loadLog(path, *options, err);
  if (!data) return kExitBadInput;

  nlohmann::json j;
  j["file"] = path;
  j["samples"] = data->samples();
  j["sample_time_s"] = data->sampleTime;
  j["sample_rate_hz"] = data->sampleRateHz();
  j["start_time_s"] = data->startTime;
  j["duration_s"] = data->duration();
  j["closed_loop"] = data->isClosedLoop();
  j["channels"] = nlohmann::json::array();
  for (const auto& c : data->channels) {
    const auto [mn, mx] = std::minmax_element(c.values.begin(), c.values.end());
    double mean = 0;
    for (double v : c.values) mean += v;
    mean /= static_cast<double>(std::max<std::size_t>(1, c.values.size()));
    j["channels"].push_back({{"name", c.name},
                             {"unit", c.unit},
                             {"role", toString(c.role)},
                             {"min", *mn},
                             {"max", *mx},
                             {"mean", mean}});
  }
  j["metadata"] = nlohmann::json::object();
  for (const auto& [k, v] : data->metadata) j["metadata"][k] = v;
  j["ranges"] = {{"estimation", rangeJson(*data, data->estimationRange)},
                 {"validation", rangeJson(*data, data->validationRange)}};
  if (args.flag("json")) {
    out << j.dump(2) << "\n";
    return kExitOk;
  }
  out << path << "\n  " << data->samples() << " samples at " << data->sampleRateHz()
      << " Hz, " << data->duration() << " s" << (data->isClosedLoop() ? ", closed loop" : "")
      << "\n  channels:\n";
  for (const auto& c : j["channels"])
    out << "    " << c["name"].get<std::string>() << " [" << c["unit"].get<std::string>() << "] "
        << c["role"].get<std::string>() << "  min " << c["min"].get<double>() << "  max "
        << c["max"].get<double>() << "\n";
  for (const auto& [k, v] : data->metadata) out << "  " << k << ": " << v << "\n";
  for (const char* which : {"estimation", "validation"}) {
    const auto& r = j["ranges"][which];
    if (!r.is_null())
      out << "  " << which << " range: " << r["start_s"].get<double>() << " - "
          << r["end_s"].get<double>() << " s (" << r["samples"].get<std::size_t>()
          << " samples)\n";
  }
  return kExitOk;
}

}  // namespace flexarm::cli
