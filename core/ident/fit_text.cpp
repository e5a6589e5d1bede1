#include "core/ident/fit_text.h"

#include "core/common/text.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>

namespace flexarm {

namespace {

// printf-style text of one value.
std::string format(const char* spec, double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, spec, v);
  return buf;
}

std::string fileName(const std::string& path) { return std::filesystem::path(path).filename().string(); }

}  // namespace

std::string frequencyList(const std::vector<double>& omega) {
  std::string text;
  for (double w : omega) text += (text.empty() ? "" : ", ") + format("%.1f", w);
  return text.empty() ? "none" : text + " rad/s";
}

namespace {
// A state-space fit's start: the subspace method, the order and why, the singular values.
std::string subspaceStart(const SubspaceEstimate& e) {
  std::string s = "subspace (" + std::string(toString(e.method)) + ", horizon " + std::to_string(e.horizon) + "), " +
                  e.orderReason + "; singular values";
  for (std::size_t i = 0; i < std::min<std::size_t>(e.singularValues.size(), 16); ++i)
    s += " " + shortNumber(e.singularValues[i]);
  return s;
}
}  // namespace

std::string fitResultText(const FitResult& fit, const FitLogNames& logs) {
  std::ostringstream out;
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
  if (fit.subspace && fit.subspace->ok) out << "start: " << subspaceStart(*fit.subspace) << "\n";
  if (fit.idim && fit.idimNote.empty())
    out << "inverse dynamics: " << fit.idim->message << ", the torque explained " << fit.idim->torqueFitPercent
        << " % (5.2), condition number " << fit.idim->conditionNumber << "\n";
  for (const auto& p : fit.parameters) {
    out << "  " << p.name << " = " << p.value;
    // An undetermined parameter's std is not quoted (0 or nan would claim what the data do not say).
    if (!p.determined && (!std::isfinite(p.std) || p.std <= 0.0)) out << " (undetermined: " << p.undetermined << ")";
    else out << " +- " << p.std << (p.determined ? "" : " (undetermined: " + p.undetermined + ")");
    out << (p.free ? "" : " (fixed)") << (p.effect.empty() ? "" : " " + p.unit + " (" + p.effect + ")") << "\n";
  }
  if (!fit.undeterminedDirection.empty())
    out << "the direction the data fix least (relative to the values): " << fit.undeterminedDirection << "\n";
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
  return out.str();
}

std::vector<std::string> fitSummaryLines(const FitResult& r, const std::string& name, const FitLogNames& logs) {
  const auto& s = r.summary;
  std::vector<std::string> lines;
  lines.push_back(name + ": " + toString(s.termination) + " after " + std::to_string(s.iterations) + " iterations in " +
                  format("%.2f", r.seconds) + " s (" + r.data.note() + ").");
  if (r.method) lines.push_back("Closed loop: " + r.methodDescription + " (" + r.methodReason + ").");
  if (!r.controllerSource.empty()) lines.push_back("Controller: " + r.controllerSource + ".");
  lines.push_back("Loss " + format("%.5g", s.loss) + ", FPE " + format("%.5g", s.fpe) + ", AIC " +
                  format("%.5g", s.aic) + ".");
  // Both fit percentages, named: the seed's (5.2) and the NRMSE fit MATLAB's compare prints.
  std::string fits = r.fitEstimation ? "Fit " + format("%.1f", *r.fitEstimation) + " % (5.2), " +
                                           format("%.1f", r.fitEstimationNrmse.value_or(NAN)) +
                                           " % NRMSE on the estimation data"
                                     : "No fit % (the simulated output diverges)";
  if (auto v = r.fitValidation())
    fits += ", " + format("%.1f", *v) + " % (5.2), " + format("%.1f", r.fitValidationNrmse().value_or(NAN)) +
            " % NRMSE on the validation data.";
  else if (r.validation.empty())
    fits += "; no validation range set.";
  else
    fits += ".";
  lines.push_back(fits);
  // Each experiment's fit % when there are several of a kind, as `flexarm fit` lists them.
  auto listFits = [&](const char* what, const std::vector<FitValidation>& list, const std::vector<std::string>& names,
                      bool validation) {
    if (list.size() < 2) return;
    for (std::size_t i = 0; i < list.size(); ++i) {
      const PreparedData& d = list[i].data;
      const SampleRange& range = validation ? d.validation : d.estimation;
      const std::size_t given = list[i].given;
      const std::string where = (given < names.size() ? fileName(names[given]) : std::string()) + ", " +
                                format("%g", d.timeAt(range.begin)) + "-" + format("%g", d.timeAt(range.end - 1)) +
                                " s";
      const std::string head = std::string(what) + " experiment " + std::to_string(given + 1) + " (" + where + "): ";
      lines.push_back(list[i].fitPercent ? head + "fit " + format("%.1f", *list[i].fitPercent) + " % (5.2), " +
                                               format("%.1f", list[i].fitPercentNrmse.value_or(NAN)) + " % NRMSE."
                                         : head + "no fit % (the simulated output diverges).");
    }
  };
  listFits("Estimation", r.estimation, logs.estimation, false);
  listFits("Validation", r.validation, logs.validation, true);
  lines.push_back("Notches: " + frequencyList(r.notches) + ". Peaks: " + frequencyList(r.peaks) +
                  ". (rad/s: the minima and maxima of |G(i w)|, what a click on the Bode plot reads, as flexarm "
                  "model and the reports give them)");
  if (r.deflection && r.deflection->fitPercent)
    lines.push_back("Deflection r phi_m - phi_a (arm encoder, " + format("%.3g", 1e3 * r.deflection->measuredRms) +
                    " mrad RMS) predicted from the torque: " + format("%.1f", *r.deflection->fitPercent) + " % (5.2), " +
                    format("%.1f", r.deflection->fitPercentNrmse.value_or(NAN)) + " % NRMSE; encoder skew " +
                    format("%.3g", 1e3 * r.deflection->skewSeconds) + " ms.");
  for (const auto& w : r.plausibility) lines.push_back("Implausible: " + w + ".");
  // Grouped by reason: "J_m, J_a (its std is 0: ...); d_a (it sits on a bound, ...)".
  std::vector<std::pair<std::string, std::string>> reasons;  // reason, names
  for (const auto& p : r.parameters) {
    if (p.determined) continue;
    auto it = std::find_if(reasons.begin(), reasons.end(), [&](const auto& x) { return x.first == p.undetermined; });
    if (it == reasons.end()) reasons.push_back({p.undetermined, p.name});
    else it->second += ", " + p.name;
  }
  std::string undetermined;
  for (const auto& [why, names] : reasons) undetermined += (undetermined.empty() ? "" : "; ") + names + " (" + why + ")";
  if (!undetermined.empty())
    lines.push_back("Undetermined by these data: " + undetermined +
                    (r.undeterminedDirection.empty() ? std::string(".")
                                                     : ". The data fix least the combination " + r.undeterminedDirection +
                                                           " (relative to the values): fix one of them, or log an "
                                                           "experiment that excites it."));
  if (!r.idimNote.empty()) lines.push_back("Start: " + r.idimNote + ".");
  if (r.subspace && r.subspace->ok) lines.push_back("Start: " + subspaceStart(*r.subspace) + ".");
  for (const auto& w : r.warnings) lines.push_back("Note: " + w + ".");
  return lines;
}

}  // namespace flexarm
