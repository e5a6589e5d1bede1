#pragma once
// Which order: a scan over ARX structures (4.11) as MATLAB's arxstruc and selstruc define it,
// and the singular values and MDL of the state-space orders (subspace.h), on the data a fit of
// the same options would use (prepareFit). `flexarm fit LOG --model arx:NA,NB,NK --scan`, the
// Fit panel's Scan orders.
//   - every na in 0..NA, nb in 1..NB, nk in NK_MIN..NK is estimated by least squares on the
//     estimation experiments; its loss V is the mean squared one-step prediction error on the
//     validation experiments (on the estimation data when there are none);
//   - picks: the least V (selstruc(V, 0), only with validation data), the least AIC
//     log V + 2 d / N and the least MDL log V + log(1 + d log N / N) with d = na + nb and N
//     the estimation samples (selstruc 'aic' and 'mdl', whose V(1 + d log N / N) this is the
//     log of);
//   - one QR of the regressors of every lag up to the largest order gives every structure's
//     least-squares problem as a small one on its rows (the loss of a column subset of
//     [Phi y] = Q R is ||R_y - R_S theta||^2), so the scan costs about one fit of the largest.
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/common/progress.h"
#include "core/ident/fit.h"
#include "core/ident/subspace.h"

namespace flexarm {

struct OrderScanOptions {
  static constexpr int kMaxOrder = 60;
  int maxNa = 10, maxNb = 10;  // na 0..maxNa, nb 1..maxNb (0: no ARX structures)
  int minNk = 1, maxNk = 1;    // delays
  int maxStateOrder = 12;      // state-space orders 1..maxStateOrder (0: none)
  bool isValid(std::string* why) const;
  // The scan's bounds from a model spec: arx:NA,NB,NK scans na <= NA, nb <= NB, nk 1..NK; ss:N
  // (or ss) the state-space orders up to N (12) alone. Nullopt with a sentence for others.
  static std::optional<OrderScanOptions> fromSpec(const FitModelSpec& spec, std::string* why);
};

struct ArxScanRow {
  int na = 0, nb = 0, nk = 0;
  double loss = 0.0;  // V
  double aic = 0.0, mdl = 0.0;
};

struct OrderScan {
  bool ok = false;
  std::string message;          // why not, when !ok
  std::string data;             // what the scan ran on (PreparedData::note)
  bool onValidation = false;    // V of the validation experiments, else of the estimation data
  long long estimationSamples = 0, lossSamples = 0;
  std::vector<ArxScanRow> rows;
  // Indices into rows; best only with validation data (-1 otherwise).
  int best = -1, bestAic = -1, bestMdl = -1;
  std::optional<SubspaceEstimate> stateSpace;  // singular values, each order's MDL, the pick
  double seconds = 0.0;
  // "arx[4 4 1]".
  std::string pickName(int index) const;
};

// The scan on options' data (options.model is not used beyond prepareFit's choices: the
// output is the motor velocity as for every black-box model). Cancelled: ok false.
OrderScan scanOrders(const FitOptions& options, const OrderScanOptions& scan, const ProgressCallback& progress = {});

// The scan as JSON (format "flexarm-order-scan" version 1) and as text.
nlohmann::json orderScanJson(const OrderScan& scan);
std::string orderScanText(const OrderScan& scan);

}  // namespace flexarm
