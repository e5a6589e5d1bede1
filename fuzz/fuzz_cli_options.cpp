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
#include "core/ident/fit_spec.h"
#include "core/models/effects.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::vector<std::string> args(1);
  for (std::size_t i = 0; i < size; ++i) {
    if (data[i] == 0) args.emplace_back();
    else args.back().push_back(static_cast<char>(data[i]));
  }
  using namespace flexarm::cli;
  OptionTable table("", "");
  table.add(fitOptionList(true)).add(logReadOptionList());
  ArgParser parser(table);
  if (!parser.parse(args)) return 0;
  std::ostringstream sink;
  (void)logReadOptions(parser, sink);
  (void)parser.number("cutoff");
  (void)parser.integer("max-iterations");
  (void)parser.integer("seed");
  if (auto m = parser.value("model")) {
    std::string why;
    (void)flexarm::fitModelSpecFromText(*m, true, &why);
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
