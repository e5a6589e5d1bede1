// flexarm model --model STRUCTURE [--param NAME=VALUE ...] [--json]
#include <cmath>
#include <nlohmann/json.hpp>
#include <ostream>

#include "app/cli/cli.h"
#include "app/cli/model_args.h"
#include "core/models/analysis.h"

namespace flexarm::cli {
namespace {

OptionTable modelTable() {
  OptionTable t("flexarm model [--model STRUCTURE] [--param NAME=VALUE ...] [options] [--json]",
                "Builds a physical model of the seed's chapter 3 and prints its matrices A, B, C, D (seed state "
                "coordinates), poles, transmission zeros, the transfer function, and the notch and peak "
                "frequencies in rad/s.");
  t.add(modelOptionList())
      .add(numberOption("damping-limit", "Z", 0.0, 1e308, "0.3", "list a root pair as lightly damped when |damping "
                                                                 "ratio| < Z"))
      .add(choiceOption("discretize", {"zoh", "foh"}, "", "also print the discrete model (needs --sample-time)"))
      .add(numberOption("sample-time", "T", 0.0, 1e308, "", "sample time in seconds for --discretize"))
      .add(textOption("bode", "W0:W1:N", "frequency response at N log-spaced frequencies W0..W1 rad/s"))
      .add(flagOption("json", "print everything as JSON"));
  t.note("Notches and peaks (JSON notches_rad_s, peaks_rad_s) are the frequencies of the local minima and maxima "
         "of |G(i w)|, at least 1 dB deep: what a click on the Bode plot reads and what `flexarm fit`, the panels "
         "and the reports print for the same model. For a lightly damped pair they lie near the imaginary part of "
         "the zero (notch) or pole (peak), which (5.4) approximates; those roots are listed apart (JSON "
         "lightly_damped_zeros, lightly_damped_poles, with their damping ratios).");
  t.note("Example: flexarm model --model two-mass --json   (Table 5.2: notch near 112 rad/s)");
  return t;
}

nlohmann::json matrixJson(const Eigen::MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (int i = 0; i < m.rows(); ++i) {
    nlohmann::json row = nlohmann::json::array();
    for (int j = 0; j < m.cols(); ++j) row.push_back(m(i, j));
    rows.push_back(row);
  }
  return rows;
}

nlohmann::json rootsJson(const std::vector<std::complex<double>>& roots) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& r : roots) a.push_back({{"re", r.real()}, {"im", r.imag()}});
  return a;
}

nlohmann::json modesJson(const std::vector<Mode>& modes) {
  nlohmann::json a = nlohmann::json::array();
  for (const auto& m : modes)
    a.push_back({{"frequency_rad_s", m.frequency},
                 {"natural_frequency_rad_s", m.naturalFrequency},
                 {"damping", m.damping}});
  return a;
}

nlohmann::json stateSpaceJson(const StateSpace& s) {
  return {{"A", matrixJson(s.A)}, {"B", matrixJson(s.B)}, {"C", matrixJson(s.C)},
          {"D", matrixJson(s.D)}, {"sample_time_s", s.sampleTime}};
}

bool parseBode(const std::string& text, double& w0, double& w1, long& n) {
  char extra = 0;
  return std::sscanf(text.c_str(), "%lf:%lf:%ld%c", &w0, &w1, &n, &extra) == 3 && w0 > 0.0 &&
         w1 > w0 && n >= 2 && n <= 100000;
}

}  // namespace

int runModel(const std::vector<std::string>& argv, std::ostream& out, std::ostream& err) {
  ArgParser args(modelTable());
  if (auto rc = parseArguments(args, argv, "model", out, err)) return *rc;
  if (!args.positional().empty()) {
    err << "flexarm model: unexpected argument '" << args.positional()[0] << "'\n";
    return kExitUsage;
  }
  const double limit = args.number("damping-limit"), sampleTime = args.number("sample-time");
  std::optional<Discretization> method;
  if (auto d = args.value("discretize")) {
    method = discretizationFromString(*d);
    if (!(sampleTime > 0.0)) {
      err << "flexarm model: --discretize needs --sample-time T > 0\n";
      return kExitUsage;
    }
  }
  double w0 = 0.0, w1 = 0.0;
  long nBode = 0;
  if (auto b = args.value("bode"); b && !parseBode(*b, w0, w1, nBode)) {
    err << "flexarm model: --bode expects W0:W1:N with 0 < W0 < W1 and 2 <= N, got '" << *b
        << "'\n";
    return kExitUsage;
  }
  auto model = modelFromArgs(args, "model", err);
  if (!model) return kExitUsage;
  const StateSpace ss = model->stateSpace();
  std::string why;
  if (!ss.isValid(&why)) {
    err << "flexarm model: the matrices are not usable: " << why << "\n";
    return kExitNumerical;
  }
  const auto p = poles(ss);
  const auto z = zeros(ss);
  const auto tf = transferFunction(ss);
  const auto dampedZeros = lightlyDamped(z, limit);
  const auto dampedPoles = lightlyDamped(p, limit);
  const NotchesPeaks np = notchesAndPeaks(ss);
  nlohmann::json j = modelJson(*model);
  j["states"] = model->stateNames();
  j["outputs"] = model->outputNames();
  j["continuous"] = stateSpaceJson(ss);
  j["poles"] = rootsJson(p);
  j["zeros"] = rootsJson(z);
  j["transfer_function"] = {{"num", tf.num}, {"den", tf.den}, {"output", model->outputNames()[0]},
                            {"input", "u (torque reference)"}};
  j["notches_rad_s"] = np.notches;
  j["peaks_rad_s"] = np.peaks;
  j["lightly_damped_zeros"] = modesJson(dampedZeros);
  j["lightly_damped_poles"] = modesJson(dampedPoles);
  if (method) j["discrete"] = stateSpaceJson(discretize(ss, sampleTime, *method));
  if (nBode > 0) {
    std::vector<double> w;
    for (long i = 0; i < nBode; ++i)
      w.push_back(w0 * std::pow(w1 / w0, static_cast<double>(i) / (nBode - 1)));
    nlohmann::json bode = nlohmann::json::array();
    const auto h = frequencyResponse(ss, w);
    for (std::size_t i = 0; i < w.size(); ++i)
      bode.push_back({{"omega_rad_s", w[i]},
                      {"magnitude_db", 20.0 * std::log10(std::abs(h[i]))},
                      {"phase_deg", std::arg(h[i]) * 180.0 / M_PI}});
    j["bode"] = bode;
  }
  if (args.flag("json")) {
    out << j.dump(2) << "\n";
    return kExitOk;
  }
  out << model->structureName() << ": " << model->description() << "\n\nParameters:\n";
  for (const auto& q : model->parameters())
    out << "  " << q.name << " = " << q.value << " " << q.unit << (q.free ? "" : " (fixed)") << "\n";
  out << "\nStates: ";
  for (const auto& s : model->stateNames()) out << s << "  ";
  out << "\n\nA =\n" << ss.A << "\nB =\n" << ss.B << "\nC =\n" << ss.C << "\nD =\n" << ss.D << "\n";
  auto printRoots = [&out](const char* title, const std::vector<std::complex<double>>& r) {
    out << "\n" << title << ":";
    for (const auto& v : r) out << "  " << v.real() << (v.imag() < 0 ? "-" : "+") << std::abs(v.imag()) << "i";
    out << "\n";
  };
  printRoots("Poles", p);
  printRoots("Zeros", z);
  out << "\nNotches (rad/s, minima of |G(i w)|):";
  for (double w : np.notches) out << " " << w;
  out << "\nPeaks (rad/s, maxima of |G(i w)|):";
  for (double w : np.peaks) out << " " << w;
  out << "\nLightly damped zeros (Im rad/s, damping):";
  for (const auto& m : dampedZeros) out << " " << m.frequency << " (" << m.damping << ")";
  out << "\nLightly damped poles (Im rad/s, damping):";
  for (const auto& m : dampedPoles) out << " " << m.frequency << " (" << m.damping << ")";
  out << "\n";
  return kExitOk;
}

}  // namespace flexarm::cli
