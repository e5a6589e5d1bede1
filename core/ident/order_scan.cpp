#include "core/ident/order_scan.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/common/text.h"
#include "core/ident/fit_internal.h"

namespace flexarm {

bool OrderScanOptions::isValid(std::string* why) const {
  auto fail = [&](const std::string& w) {
    if (why) *why = w;
    return false;
  };
  if (maxNa < 0 || maxNa > kMaxOrder || maxNb < 0 || maxNb > kMaxOrder)
    return fail("the scan takes na and nb up to " + std::to_string(kMaxOrder) + " (nb 0: no ARX structures)");
  if (minNk < 0 || maxNk < minNk || maxNk > kMaxOrder)
    return fail("the scan's delays must run from nk >= 0 up to at most " + std::to_string(kMaxOrder));
  if (maxStateOrder < 0 || maxStateOrder > SubspaceOptions::kMaxOrder)
    return fail("the state-space orders scanned must be at most " + std::to_string(SubspaceOptions::kMaxOrder));
  return true;
}

std::optional<OrderScanOptions> OrderScanOptions::fromSpec(const FitModelSpec& spec, std::string* why) {
  OrderScanOptions o;
  if (spec.kind == FitModelKind::BlackBox && spec.structure == PolyStructure::Arx) {
    o.maxNa = spec.orders.na;
    o.maxNb = spec.orders.nb;
    o.minNk = std::min(1, spec.orders.nk);
    o.maxNk = spec.orders.nk;
  } else if (spec.kind == FitModelKind::BlackBox && spec.structure == PolyStructure::Ss) {
    o.maxNa = 0;
    o.maxNb = 0;  // no ARX structures
    o.maxStateOrder = spec.orders.na > 0 ? spec.orders.na : o.maxStateOrder;
    return o;
  } else {
    if (why) *why = "an order scan takes arx:NA,NB,NK (na <= NA, nb <= NB, nk up to NK) or ss[:N], not " + spec.name();
    return std::nullopt;
  }
  if (!o.isValid(why)) return std::nullopt;
  return o;
}

std::string OrderScan::pickName(int index) const {
  if (index < 0 || index >= static_cast<int>(rows.size())) return "";
  const ArxScanRow& r = rows[static_cast<std::size_t>(index)];
  return "arx[" + std::to_string(r.na) + " " + std::to_string(r.nb) + " " + std::to_string(r.nk) + "]";
}

namespace {

// The triangular factor of [Phi y] over every experiment's rows from `first` on, with
// Phi = [-y(t-1) .. -y(t-maxNa), u(t-minNk) .. u(t-maxLag)].
Eigen::MatrixXd regressionFactor(const std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>>& experiments,
                                 int maxNa, int minNk, int maxLag, int first, long long* rowsOut) {
  const int cols = maxNa + (maxLag - minNk + 1);
  Eigen::Index rows = 0;
  for (const auto& [u, y] : experiments) rows += std::max<Eigen::Index>(0, y.size() - first);
  if (rowsOut) *rowsOut = rows;
  Eigen::MatrixXd M(rows, cols + 1);
  Eigen::Index at = 0;
  for (const auto& [u, y] : experiments)
    for (Eigen::Index t = first; t < y.size(); ++t, ++at) {
      for (int k = 1; k <= maxNa; ++k) M(at, k - 1) = -y[t - k];
      for (int k = minNk; k <= maxLag; ++k) M(at, maxNa + k - minNk) = u[t - k];
      M(at, cols) = y[t];
    }
  Eigen::HouseholderQR<Eigen::MatrixXd> qr(M);
  const Eigen::Index k = std::min<Eigen::Index>(M.rows(), M.cols());
  return qr.matrixQR().topRows(k).triangularView<Eigen::Upper>();
}

// ||R_y - R_S theta||^2 for the columns S.
double residual(const Eigen::MatrixXd& R, const std::vector<int>& S, const Eigen::VectorXd& theta) {
  Eigen::VectorXd r = R.col(R.cols() - 1);
  for (std::size_t i = 0; i < S.size(); ++i) r -= theta[static_cast<Eigen::Index>(i)] * R.col(S[i]);
  return r.squaredNorm();
}

}  // namespace

OrderScan scanOrders(const FitOptions& given, const OrderScanOptions& scan, const ProgressCallback& progress) {
  std::string why;
  if (!scan.isValid(&why)) throw std::invalid_argument("scanOrders: " + why);
  const auto t0 = std::chrono::steady_clock::now();
  OrderScan out;
  FitOptions options = given;
  // The data a black-box fit sees: the motor velocity, the means removed.
  options.model = FitModelSpec{};
  options.model.kind = FitModelKind::BlackBox;
  options.model.structure = PolyStructure::Arx;
  options.method = FitMethod::PredictionError;
  PreparedFit prepared = prepareFit(options);
  if (!prepared.ok) {
    out.message = prepared.result.message;
    return out;
  }
  const FitResult& r = prepared.result;
  out.data = r.data.note();
  std::vector<std::pair<Eigen::VectorXd, Eigen::VectorXd>> est, val;
  for (const auto& e : r.estimation) est.emplace_back(e.data.estimationInput(), e.data.estimationOutput());
  for (const auto& v : r.validation) {
    const SampleRange& g = v.data.validation;
    const auto b = static_cast<Eigen::Index>(g.begin), n = static_cast<Eigen::Index>(g.size());
    val.emplace_back(v.data.u.segment(b, n), v.data.y.segment(b, n));
  }
  out.onValidation = !val.empty();

  if (scan.maxNb >= 1) {
    const int maxLag = scan.maxNk + scan.maxNb - 1;
    const int first = std::max(scan.maxNa, maxLag);
    long long estRows = 0, valRows = 0;
    Eigen::Index shortest = std::numeric_limits<Eigen::Index>::max();
    for (const auto& e : est) shortest = std::min(shortest, e.second.size());
    for (const auto& v : val) shortest = std::min(shortest, v.second.size());
    const int cols = scan.maxNa + maxLag - scan.minNk + 1;
    if (shortest <= first + 1) {
      out.message = "an experiment has " + std::to_string(shortest) + " samples, too few for lags up to " +
                    std::to_string(first) + "; lower the scan's orders";
      return out;
    }
    const Eigen::MatrixXd Re = regressionFactor(est, scan.maxNa, scan.minNk, maxLag, first, &estRows);
    if (estRows <= 2 * cols) {
      out.message = "too few estimation samples (" + std::to_string(estRows) + ") for ARX structures of up to " +
                    std::to_string(cols) + " parameters";
      return out;
    }
    Eigen::MatrixXd Rv;
    if (out.onValidation) Rv = regressionFactor(val, scan.maxNa, scan.minNk, maxLag, first, &valRows);
    out.estimationSamples = estRows;
    out.lossSamples = out.onValidation ? valRows : estRows;
    const double N = static_cast<double>(estRows);
    double bestV = std::numeric_limits<double>::infinity(), bestA = bestV, bestM = bestV;
    const int total = (scan.maxNa + 1) * scan.maxNb * (scan.maxNk - scan.minNk + 1);
    int done = 0;
    for (int nk = scan.minNk; nk <= scan.maxNk; ++nk)
      for (int na = 0; na <= scan.maxNa; ++na)
        for (int nb = 1; nb <= scan.maxNb; ++nb, ++done) {
          if (done % 50 == 0 && reportProgress(progress, static_cast<double>(done) / total, "scanning orders")) {
            out.message = "cancelled by the user";
            return out;
          }
          std::vector<int> S;
          for (int k = 0; k < na; ++k) S.push_back(k);
          for (int k = 0; k < nb; ++k) S.push_back(scan.maxNa + nk - scan.minNk + k);
          Eigen::MatrixXd A(Re.rows(), static_cast<Eigen::Index>(S.size()));
          for (std::size_t i = 0; i < S.size(); ++i) A.col(static_cast<Eigen::Index>(i)) = Re.col(S[i]);
          Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
          if (qr.rank() < A.cols()) continue;  // not identifiable from these data
          const Eigen::VectorXd theta = qr.solve(Eigen::VectorXd(Re.col(Re.cols() - 1)));
          ArxScanRow row;
          row.na = na;
          row.nb = nb;
          row.nk = nk;
          const double Ve = residual(Re, S, theta) / N;
          row.loss = out.onValidation ? residual(Rv, S, theta) / static_cast<double>(valRows) : Ve;
          const double d = na + nb;
          const double logV = std::log(std::max(row.loss, 1e-300));
          row.aic = logV + 2.0 * d / N;
          row.mdl = logV + std::log1p(d * std::log(N) / N);
          out.rows.push_back(row);
          const int i = static_cast<int>(out.rows.size()) - 1;
          if (out.onValidation && row.loss < bestV) {
            bestV = row.loss;
            out.best = i;
          }
          if (row.aic < bestA) {
            bestA = row.aic;
            out.bestAic = i;
          }
          if (row.mdl < bestM) {
            bestM = row.mdl;
            out.bestMdl = i;
          }
        }
  }
  if (scan.maxStateOrder > 0) {
    const fit_detail::JoinedEstimation j = fit_detail::joinedEstimation(r);
    SubspaceOptions so;
    so.maxOrder = scan.maxStateOrder;
    so.closedLoop = r.data.closedLoop;
    so.experimentLengths = j.lengths;
    out.stateSpace = subspaceEstimate(j.u, j.y, r.data.sampleTime, so);
    if (out.estimationSamples == 0) out.estimationSamples = j.y.size();
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (out.rows.empty() && !(out.stateSpace && out.stateSpace->ok)) {
    out.message = out.stateSpace ? out.stateSpace->message : "no structure could be estimated from these data";
    return out;
  }
  out.ok = true;
  return out;
}

nlohmann::json orderScanJson(const OrderScan& s) {
  using nlohmann::json;
  auto fin = [](double v) { return std::isfinite(v) ? json(v) : json(nullptr); };
  json j = {{"format", "flexarm-order-scan"}, {"version", 1}, {"ok", s.ok}, {"message", s.message}};
  if (!s.ok) return j;
  json rows = json::array();
  for (const auto& r : s.rows)
    rows.push_back({{"na", r.na}, {"nb", r.nb}, {"nk", r.nk}, {"loss", fin(r.loss)}, {"aic", fin(r.aic)},
                    {"mdl", fin(r.mdl)}});
  auto pick = [&](int i) { return i >= 0 ? json(s.pickName(i)) : json(nullptr); };
  j.update({{"data", s.data},
            {"loss_on", s.onValidation ? "validation" : "estimation"},
            {"samples_estimation", s.estimationSamples},
            {"samples_loss", s.lossSamples},
            {"arx", rows},
            {"best_validation", pick(s.best)},
            {"best_aic", pick(s.bestAic)},
            {"best_mdl", pick(s.bestMdl)},
            {"seconds", s.seconds}});
  if (s.stateSpace) {
    const SubspaceEstimate& e = *s.stateSpace;
    json orders = json::array();
    for (const auto& o : e.orders)
      orders.push_back({{"order", o.order}, {"loss", fin(o.loss)}, {"mdl", fin(o.mdl)},
                        {"stable_predictor", o.stablePredictor}});
    j["state_space"] = {{"ok", e.ok},         {"message", e.message},
                        {"method", toString(e.method)}, {"horizon", e.horizon},
                        {"singular_values", e.singularValues}, {"orders", orders},
                        {"chosen_order", e.ok ? json(e.chosenOrder) : json(nullptr)},
                        {"order_reason", e.orderReason}};
  }
  return j;
}

std::string orderScanText(const OrderScan& s) {
  std::ostringstream out;
  if (!s.ok) {
    out << "order scan: " << s.message << "\n";
    return out.str();
  }
  out << "order scan on " << s.estimationSamples << " estimation samples (" << s.data << ")";
  if (!s.rows.empty())
    out << ", loss V on the " << (s.onValidation ? "validation" : "estimation") << " data (" << s.lossSamples
        << " samples)";
  out << "\n";
  if (!s.rows.empty()) {
    // The best structure of each parameter count d = na + nb, as selstruc's plot shows them.
    std::vector<int> bestOf;
    for (std::size_t i = 0; i < s.rows.size(); ++i) {
      const std::size_t d = static_cast<std::size_t>(s.rows[i].na + s.rows[i].nb);
      if (bestOf.size() <= d) bestOf.resize(d + 1, -1);
      if (bestOf[d] < 0 || s.rows[i].loss < s.rows[static_cast<std::size_t>(bestOf[d])].loss)
        bestOf[d] = static_cast<int>(i);
    }
    out << "  d   best structure   V              AIC        MDL\n";
    for (std::size_t d = 0; d < bestOf.size(); ++d) {
      if (bestOf[d] < 0) continue;
      const ArxScanRow& r = s.rows[static_cast<std::size_t>(bestOf[d])];
      char line[160];
      std::snprintf(line, sizeof line, "  %-3zu %-16s %-14.6g %-10.5f %-10.5f\n", d, s.pickName(bestOf[d]).c_str(),
                    r.loss, r.aic, r.mdl);
      out << line;
    }
    if (s.best >= 0) out << "least validation loss (selstruc 0): " << s.pickName(s.best) << "\n";
    out << "least AIC: " << s.pickName(s.bestAic) << "\nleast MDL: " << s.pickName(s.bestMdl) << "\n";
  }
  if (s.stateSpace) {
    const SubspaceEstimate& e = *s.stateSpace;
    if (!e.ok) {
      out << "state space: " << e.message << "\n";
    } else {
      out << "state space (" << toString(e.method) << ", horizon " << e.horizon << "): " << e.orderReason
          << "\n  singular values:";
      for (std::size_t i = 0; i < std::min<std::size_t>(e.singularValues.size(), 20); ++i)
        out << " " << shortNumber(e.singularValues[i]);
      out << "\n";
    }
  }
  return out.str();
}

}  // namespace flexarm
