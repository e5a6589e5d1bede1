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

const char* kBodeHelp =
    "Usage: flexarm bode LOG --model SPEC --out bode.csv [options] [--json]\n\n"
    "Fits a model as `flexarm fit` does (or estimates SPA/ETFE) and writes its frequency\n"
    "response with confidence band limits to a CSV file: omega_rad_s, frequency_hz,\n"
    "magnitude, magnitude_db, phase_deg, magnitude_lower, magnitude_upper, phase_lower_deg,\n"
    "phase_upper_deg (band columns empty where there is no covariance, e.g. ETFE).\n\n"
    "  --model spa[:M]       non-parametric SPA (4.28), Hann lag window of width M\n"
    "                        (default: chosen from the data, 1 s of lags and at most N/10,\n"
    "                        SITB's min(N/10, 30) when 1 s is under 30 samples; the note\n"
    "                        and JSON message say which and why)\n"
    "  --model etfe[:W]      ETFE (4.24) smoothed over W bins (4.25)\n"
    "  --out FILE            the CSV file to write (required)\n"
    "  --level P             confidence level of the bands (default 0.99)\n"
    "  --points N            number of frequencies, logarithmically spaced (default 500);\n"
    "                        SPA leaves out those where the input has no power (counted\n"
    "                        as omitted_frequencies)\n"
    "  --wmin W --wmax W     frequency range in rad/s (default 2 pi/(N T) .. pi/T)\n";

}  // namespace

int runBode(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  std::vector<std::string> valued = fitValuedOptionNames();
  for (const char* n : {"out", "level", "points", "wmin", "wmax"}) valued.push_back(n);
  ArgParser args(fitFlagNames(), valued);
  if (!args.parse(argv)) {
    err << "flexarm bode: " << args.error() << "\n" << kBodeHelp << fitOptionsHelp();
    return kExitUsage;
  }
  if (args.flag("help")) {
    out << kBodeHelp << fitOptionsHelp() << "\n" << logReadOptionsHelp();
    return kExitOk;
  }
  auto outPath = args.value("out");
  if (!outPath) {
    err << "flexarm bode: --out bode.csv is required\n";
    return kExitUsage;
  }
  double level = 0.99, wmin = 0.0, wmax = 0.0;
  int points = 500;
  if (!args.number("level", level) || !args.integer("points", points, 2, 1000000) ||
      !args.number("wmin", wmin) || !args.number("wmax", wmax)) {
    err << "flexarm bode: " << args.error() << "\n";
    return kExitUsage;
  }
  if (!(level > 0.0 && level < 1.0) || points < 2) {
    err << "flexarm bode: --level must lie strictly between 0 and 1 and --points be at least 2\n";
    return kExitUsage;
  }
  FitResult fit;
  if (const int rc = runFitPipeline(args, "bode", fit, err, true); rc != kExitOk) return rc;
  const double T = fit.data.sampleTime;
  if (!args.value("wmin")) wmin = 2.0 * M_PI / (static_cast<double>(fit.data.estimation.size()) * T);
  if (!args.value("wmax")) wmax = M_PI / T;
  if (!(wmin > 0.0) || !(wmax > wmin)) {
    err << "flexarm bode: need 0 < --wmin < --wmax\n";
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
  if (!writeFileAtomically(*outPath, csv.str(), &why)) {
    err << "flexarm bode: " << why << "\n";
    return kExitBadInput;
  }
  const std::string name = fit.modelName();
  // The fit's rule (non-parametric curves ripple: only extrema 3 dB deep count there).
  const auto np = fitNotchesAndPeaks(fit, fr, FitOptions{}.notchDepthDb);
  if (args.flag("json")) {
    nlohmann::json j = {{"model", name},
                        {"output", *outPath},
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
    out << "wrote " << *outPath << ": " << fr.omega.size() << " frequencies of " << name
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
