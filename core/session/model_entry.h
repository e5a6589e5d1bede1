#pragma once
// A model of the shared model list, without Qt: a physical model (its parameters, free/fixed
// flags and output options) with the nonlinear effects switched on for it, or a black-box
// estimate, and where it came from: by hand, a fit (its request, which data, which ranges,
// which rate), a discovery, or a session. The widgets show these; the evaluations take them
// as EvaluatedModel (core/ident/model_output.h).
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Dense>

#include "core/ident/blackbox.h"
#include "core/ident/model_output.h"
#include "core/models/effects.h"
#include "core/models/physical_models.h"
#include "core/session/provenance.h"

namespace flexarm {

struct FitRequest;  // core/session/fit_request.h

// How an entry came into the list.
enum class ModelOrigin { Hand, Fit, Discovery, Session };
const char* toString(ModelOrigin o);  // "hand", "fit", "discovery", "session"

struct ModelEntry {
  std::string name;
  std::shared_ptr<const PhysicalModel> model;  // null for a black-box estimate
  std::vector<Effect> effects;
  // A black-box estimate (4.8) with its covariance; set exactly when model is null.
  std::shared_ptr<const PolynomialModel> polynomial;
  // For a physical estimate: covariance of the free parameters (indices into
  // model->parameters()) that gives its confidence bands. Empty for a hand-made model; an
  // edit of the parameters clears it.
  Eigen::MatrixXd covariance;
  std::vector<int> covarianceIndices;
  // For an estimate of the Fit panel: what was asked (structure, start values, free
  // parameters, options, ranges), so a session can store and replay the fit.
  std::shared_ptr<const FitRequest> fitRequest;
  ModelOrigin origin = ModelOrigin::Hand;
  // The data an estimate was computed on (a fit's or a discovery's); unset for a hand-made
  // model. A fit's is its request's.
  std::optional<Provenance> estimatedOn;
  // The speed of the smooth signs its fit used (0: the plant's default).
  double smoothingSpeed = 0.0;

  // The data it was estimated on: estimatedOn, else its fit request's.
  std::optional<Provenance> dataProvenance() const;
  // The rate its fit ran at, as a decimation of the log (1: the log's rate).
  int decimation() const;
  // The model as the evaluations take it (its name, model or estimate, effects, rate).
  EvaluatedModel evaluated() const;
  // Where it came from in words: "fit on chirp.csv 0.5-9 s at decimation 10, with
  // coulomb_friction", "by hand", "discovery on chirp.csv whole log".
  std::string provenanceText() const;
};

}  // namespace flexarm
