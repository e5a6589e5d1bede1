// libFuzzer target: a diagnosis on whatever log the bytes make (read as a FlexArm CSV log):
// the dead-data check, the diagnosis signals and chapter 7's recursive tests against a fixed
// theta_0. It must end with a result or a sentence: never crash, hang or divide by zero into a
// silent NaN verdict.
#include <cmath>
#include <cstdint>
#include <memory>
#include <string_view>

#include "core/diagnosis/diagnosis.h"
#include "core/diagnosis/reference.h"
#include "core/io/log_io.h"
#include "core/models/physical_models.h"

namespace {

struct Fixture {
  flexarm::DiagnosisOptions options;
  flexarm::DiagnosisReference reference;
  Fixture() {
    const auto model = flexarm::makeModel("three-mass");
    // theta_0 is the model as given (no log to simulate it on): the diagnosis itself is what
    // the fuzzer drives.
    reference = flexarm::referenceFromModel(*model, flexarm::IdData{}, options);
  }
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Fixture fixture;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const flexarm::LogReadResult log = flexarm::readFlexArmCsvText(text, "fuzz.csv");
  if (!log.ok || log.data.samples() > 20000) return 0;
  const flexarm::DiagnosisResult r = flexarm::diagnose(fixture.reference, log.data, fixture.options);
  if (r.termination != flexarm::Termination::Converged && r.message.empty()) __builtin_trap();
  return 0;
}
