// libFuzzer target: the command-line option parser and the option values every verb
// interprets (numbers, ranges of integers, model specs, effects, log reading options, time
// ranges), on arguments split from the input at zero bytes. The verbs themselves do not run.
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "app/cli/cli.h"
#include "app/cli/log_args.h"
#include "app/cli/verb_fit.h"
#include "core/models/effects.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == 0) args.emplace_back();
    else args.back().push_back(static_cast<char>(data[i]));
  }
  using namespace flexarm::cli;
  ArgParser parser(fitFlagNames(), fitValuedOptionNames());
  if (!parser.parse(args)) return 0;
  std::ostringstream sink;
  (void)logReadOptions(parser, sink);
  double x = 0;
  int n = 0;
  long l = 0;
  (void)parser.number("range", x);
  (void)parser.integer("max-iterations", n, 0, 100000);
  (void)parser.integer("seed", l);
  if (auto m = parser.value("model")) {
    flexarm::FitModelSpec spec;
    std::string why;
    (void)parseModelSpec(*m, spec, &why, true);
  }
  for (const auto& e : parser.values("fix")) {
    std::string why;
    (void)flexarm::parseEffect(e, &why);
  }
  flexarm::IdData d;
  d.sampleTime = 0.001;
  d.setChannel({"u", "", flexarm::ChannelRole::Input, std::vector<double>(100, 0.0)});
  if (auto r = parser.value("validation-range")) {
    flexarm::SampleRange range;
    std::string why;
    (void)parseTimeRange(*r, d, range, &why);
  }
  return 0;
}
