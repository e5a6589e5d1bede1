// flexarm bode LOG --model SPEC [options] --out bode.csv [--json]
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "app/cli/log_args.h"
#include "app/cli/verb_fit.h"
#include "core/ident/evaluation.h"
#include "core/io/log_io.h"

namespace flexarm::cli {
namespace {

OptionTable bodeTable() {
  OptionTable t("flexarm bode LOG --model SPEC --out bode.csv [options] [--json]",
                "Fits a model as `flexarm fit` does (or estimates SPA/ETFE) and writes its frequency response with "
                "confidence band limits to a CSV file: omega_rad_s, frequency_hz, magnitude, magnitude_db, "
                "phase_deg, magnitude_lower, magnitude_upper, phase_lower_deg, phase_upper_deg (band columns empty "
                "where there is no covariance, e.g. ETFE).");
  // The level and the frequencies lie strictly above 0 (the level below 1).
  auto open = [](Option o) {
    o.minOpen = true;
    o.maxOpen = o.max < 1e308;
    return o;
  };
  t.add(required(textOption("out", "FILE", "the CSV file to write")))
      .add(open(numberOption("level", "P", 0.0, 1.0, "0.99", "confidence level of the bands")))
      .add(integerOption("points", "N", 2, 1000000, "500",
                         "number of frequencies, logarithmically spaced; SPA leaves out those where the input "
                         "has no power (counted as omitted_frequencies)"))
      .add(open(numberOption("wmin", "W", 0.0, 1e308, "", "lowest frequency in rad/s (default 2 pi/(N T))")))
      .add(open(numberOption("wmax", "W", 0.0, 1e308, "", "highest frequency in rad/s (default pi/T)")))
      .group("The fit")
      .add(fitOptionList(true))
      .group("Reading the log")
      .add(logReadOptionList());
  t.note("SPA's lag window is chosen from the data unless given: 1 s of lags and at most N/10, SITB's min(N/10, "
         "30) when 1 s is under 30 samples; the note and the JSON message say which and why.");
  return t;
}

}  // namespace

int runBode(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(bodeTable());
  if (auto rc = parseArguments(args, argv, "bode", out, err)) return *rc;
  const std::string outPath = args.text("out");
  const double level = args.number("level");
  const long points = args.integer("points");
  double wmin = args.number("wmin"), wmax = args.number("wmax");
  FitResult fit;
  if (const int rc = runFitPipeline(args, "bode", fit, err, true); rc != kExitOk) return rc;
  const double T = fit.data.sampleTime;
  if (!args.value("wmin")) wmin = 2.0 * M_PI / (static_cast<double>(fit.data.estimation.size()) * T);
  if (!args.value("wmax")) wmax = M_PI / T;
  if (!(wmax > wmin)) {
    err << "flexarm bode: need --wmin < --wmax\n";
    return kExitUsage;
  }
  const auto fr = fitResponse(fit, logGrid(wmin, wmax, static_cast<int>(points)), level);
  // SPA leaves out frequencies where the input has no power.
  const long omitted = points - static_cast<long>(fr.omega.size());
  std::ostringstream csv;
  csv << std::setprecision(10);
  csv << "omega_rad_s,frequency_hz,magnitude,magnitude_db,phase_deg,magnitude_lower,"
         "magnitude_upper,phase_lower_deg,phase_upper_deg\n";
  const double deg = 180.0 / M_PI;
  for (std::size_t i = 0; i < fr.omega.size(); ++i) {
    csv << fr.omega[i] << "," << fr.omega[i] / (2 * M_PI) << "," << fr.magnitude[i] << ","
        << 20.0 * std::log10(fr.magnitude[i]) << "," << fr.phase[i] * deg << ",";
    if (fr.hasBands())
      csv << fr.magnitudeLower[i] << "," << fr.magnitudeUpper[i] << ","
          << fr.phaseLower[i] * deg << "," << fr.phaseUpper[i] * deg << "\n";
    else
      csv << ",,,\n";
  }
  std::string why;
  if (!writeFileAtomically(outPath, csv.str(), &why)) {
    err << "flexarm bode: " << why << "\n";
    return kExitBadInput;
  }
  const std::string name = fit.modelName();
  // The fit's rule (non-parametric curves ripple: only extrema 3 dB deep count there).
  const auto np = fitNotchesAndPeaks(fit, fr, FitOptions{}.notchDepthDb);
  if (args.flag("json")) {
    nlohmann::json j = {{"model", name},
                        {"output", outPath},
                        {"points", fr.omega.size()},
                        {"level", level},
                        {"bands", fr.hasBands()},
                        {"notches_rad_s", np.notches},
                        {"peaks_rad_s", np.peaks},
                        {"warning", fit.nonparametric.warning},
                        {"message", fit.summary.message},
                        {"lag_window", fit.model.kind == FitModelKind::Spa ? nlohmann::json(fit.nonparametric.window)
                                                                             : nlohmann::json(nullptr)},
                        {"omitted_frequencies", omitted}};
    out << j.dump(2) << "\n";
  } else {
    out << "wrote " << outPath << ": " << fr.omega.size() << " frequencies of " << name
        << (fr.hasBands() ? " with bands" : "") << "\n";
    if (fit.model.kind == FitModelKind::Spa) out << "note: " << fit.summary.message << "\n";
    if (!fit.nonparametric.warning.empty())
      out << "warning: " << fit.nonparametric.warning << "\n";
    if (omitted > 0)
      out << "note: left out " << omitted << " of " << points
          << " frequencies where the smoothed input spectrum is not positive or below 1e-2 of "
             "its peak (the input has almost no power there)\n";
  }
  return kExitOk;
}

}  // namespace flexarm::cli
