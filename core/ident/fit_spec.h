#pragma once
// What a fit estimates, named as a user names it: the model-spec grammar of `flexarm fit
// --model`, `flexarm bode --model` and the names results carry, and the parameters of a
// physical fit by the names its parameter table prints. One grammar for the command line, the
// Fit panel and sessions:
//   arx:NA,NB,NK  armax:NA,NB,NC,NK  oe:NB,NF,NK  bj:NB,NC,ND,NF,NK   black-box (4.8), delay NK
//   arx[4 4 1] ... bj[2 2 2 2 1]                                    the same, as names print
//   ss:N | ss[N] | ss                                               state space of order N
//                                                                   (subspace.h); ss: N by MDL
//   rigid | two-mass | three-mass | four-mass | two-mass-theta      a physical model (chapter 3)
//                                                                   from its nominal values
//   spa[:M] | etfe[:W]                                              non-parametric (4.28), (4.24)
#include <optional>
#include <string>
#include <vector>

#include "core/ident/fit.h"

namespace flexarm {

// The physical structures a spec may name (core/models), in the order a list shows them.
bool isPhysicalModelName(const std::string& name);

// The spec text names; nullopt with a sentence for malformed text. Non-parametric specs only
// when allowNonparametric (SPA and ETFE give a response, no model to keep).
std::optional<FitModelSpec> fitModelSpecFromText(const std::string& text, bool allowNonparametric,
                                                 std::string* why);
// The spec as `--model` takes it: "oe:2,2,1", "three-mass", "spa:60" ("spa" for the default
// window). A physical spec names its start's structure; effects are not part of it.
std::string fitModelSpecText(const FitModelSpec& spec);
// The grammar in a line for help texts: "arx:NA,NB,NK | armax:NA,NB,NC,NK | ... | rigid|two-mass|...".
std::string fitModelSpecGrammar(bool allowNonparametric);

// A parameter as a physical fit's table and the Fit panel list label it: "J_m", or an
// effect's "beta (nonlinear_spring)".
std::string fitParameterLabel(const std::string& name, const std::string& effect);
std::string fitParameterLabel(const FitParameter& parameter);
// Every parameter of a physical spec's start model and effects by label, and the free ones.
std::vector<std::string> fitParameterLabels(const FitModelSpec& spec);
std::vector<std::string> freeParameterLabels(const FitModelSpec& spec);
// The parameter names of a physical spec's model and effects as a message lists them
// ("J_m, J_a, f_m, k_a, d_a, r, k_T").
std::string fitParameterNames(const FitModelSpec& spec);

// Where a parameter named by the user lives in a physical spec: the start model's index, or
// an effect and its value (names as the table prints them, or labels "beta (nonlinear_spring)").
struct FitParameterRef {
  int model = -1;   // index into start->parameters()
  int effect = -1;  // index into effects
  int value = -1;   // index into effects[effect].effect.values
  bool found() const { return model >= 0 || effect >= 0; }
};
FitParameterRef findFitParameter(const FitModelSpec& spec, const std::string& nameOrLabel);
// The sentence for a name that is no parameter of the spec: "the two-mass model has no
// parameter 'k_g' (its parameters: J_m, J_a, f_m, k_a, d_a, r, k_T)".
std::string unknownFitParameter(const FitModelSpec& spec, const std::string& name);

// Makes exactly the named parameters free (the start model copied first); false with
// unknownFitParameter's sentence for a name that is none. An empty list frees nothing.
bool setFreeParameters(FitModelSpec& spec, const std::vector<std::string>& names, std::string* why);

// A parameter option of a physical fit, as `flexarm fit` takes them in command-line order (a
// later one naming a parameter overrides an earlier one):
//   Free  "P1,P2"    estimate only these (model or effect parameters)
//   Fix   "P", "P=V" hold P (at V, else its start value)
//   Start "P=V"      start P from V (a fixed P is held at V)
//   Bound "P=LO:HI"  search P only in [LO, HI] (-inf, inf allowed)
// A model parameter's value goes into options.startValues, an effect's into the effect itself
// (its second value given, the smoothing speed is no longer the data's). False with a sentence
// (and the options as they were) for a malformed option, a name that is no parameter, an
// effect value that is not physical, or a model that is not physical.
enum class ParameterOption { Free, Fix, Start, Bound };
bool applyParameterOption(FitOptions& options, ParameterOption kind, const std::string& text, std::string* why);

// An effect at its defaults (the first value free), with the values of the start model's own
// effect of that kind when it carries one (e.g. the v_s discovery found: kept, not rescaled).
FitEffect fitEffectFor(EffectKind kind, const std::vector<Effect>& own);

}  // namespace flexarm
