// `flexarm fit` without --json: the result as lines of text.
#include <cmath>
#include <ostream>

#include "app/cli/verb_fit.h"

namespace flexarm::cli {

void printFitText(std::ostream& out, const FitResult& fit, const FitLogNames& logs) {
  const auto& s = fit.summary;
  std::size_t samples = 0;  // of every estimation experiment
  for (const auto& e : fit.estimation) samples += e.data.estimation.size();
  out << fit.modelName() << ": " << toString(s.termination) << " after " << s.iterations << " iterations ("
      << s.message << ")\n";
  out << "data: " << samples << " estimation samples"
      << (fit.estimation.size() > 1 ? " in " + std::to_string(fit.estimation.size()) + " experiments" : std::string())
      << " at " << 1.0 / fit.data.sampleTime << " Hz (" << fit.data.note() << ")\n";
  if (fit.method) out << "closed-loop method: " << fit.methodDescription << " (" << fit.methodReason << ")\n";
  if (fit.controller) out << "controller: " << fit.controllerSource << "\n";
  if (!fit.idimNote.empty()) out << "start: " << fit.idimNote << "\n";
  if (fit.idim && fit.idimNote.empty())
    out << "inverse dynamics: " << fit.idim->message << ", the torque explained " << fit.idim->torqueFitPercent
        << " % (5.2), condition number " << fit.idim->conditionNumber << "\n";
  for (const auto& p : fit.parameters)
    out << "  " << p.name << " = " << p.value << " +- " << p.std << (p.free ? "" : " (fixed)")
        << (p.effect.empty() ? "" : " " + p.unit + " (" + p.effect + ")") << "\n";
  out << "loss " << s.loss << ", FPE " << s.fpe << "\n";
  // Both fit percentages, named (evaluation.h): the seed's (5.2) and MATLAB compare's NRMSE.
  auto both = [&](const std::optional<double>& seed52, const std::optional<double>& nrmse) {
    out << *seed52 << " % (5.2), " << nrmse.value_or(NAN) << " % NRMSE";
  };
  if (fit.fitEstimation) {
    out << "fit on the estimation data: ";
    both(fit.fitEstimation, fit.fitEstimationNrmse);
    out << "\n";
  }
  if (auto v = fit.fitValidation()) {
    out << "fit on the validation data: ";
    both(v, fit.fitValidationNrmse());
    out << "\n";
  }
  // Each experiment's fit % when there are several of a kind.
  auto listFits = [&](const char* what, const std::vector<FitValidation>& list, const std::vector<std::string>& names,
                      bool validation) {
    if (list.size() < 2) return;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const PreparedData& d = list[i].data;
      const SampleRange& range = validation ? d.validation : d.estimation;
      out << what << " " << i + 1 << " (" << (i < names.size() ? names[i] : std::string()) << ", "
          << d.timeAt(range.begin) << "-" << d.timeAt(range.end - 1) << " s): fit ";
      if (list[i].fitPercent) {
        both(list[i].fitPercent, list[i].fitPercentNrmse);
        out << "\n";
      } else {
        out << "undefined\n";
      }
    }
  };
  listFits("estimation", fit.estimation, logs.estimation, false);
  listFits("validation", fit.validation, logs.validation, true);
  if (fit.deflection) {
    const DeflectionCheck& c = *fit.deflection;
    out << "deflection r phi_m - phi_a (arm encoder, r = " << c.gearRatio << ", measured " << c.measuredRms * 1e3
        << " mrad RMS): predicted from the torque ";
    if (c.fitPercent) both(c.fitPercent, c.fitPercentNrmse);
    out << ", error " << c.rmsEstimation * 1e3 << " mrad RMS";
    if (c.fitPercentValidation) {
      out << "; validation ";
      both(c.fitPercentValidation, c.fitPercentValidationNrmse);
    }
    out << "\n  encoder skew " << c.skewSeconds * 1e3 << " +- " << c.skewStd * 1e3
        << " ms (arm reading late); without it " << c.fitPercentWithoutSkew.value_or(NAN) << " % (5.2)\n";
  }
  for (const auto& w : fit.warnings) out << "warning: " << w << "\n";
  for (const auto& w : fit.plausibility) out << "implausible: " << w << "\n";
  auto list = [&](const char* what, const std::vector<double>& w) {
    out << what;
    for (double x : w) out << " " << x;
    out << (w.empty() ? " none\n" : " rad/s\n");
  };
  list("notches:", fit.notches);
  list("peaks:", fit.peaks);
}

}  // namespace flexarm::cli
