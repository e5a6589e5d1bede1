// The model-spec grammar (core/ident/fit_spec.h) the command line, the Fit panel and sessions
// share, the orders each structure of (4.8) takes, parameters named as the table prints them,
// and the codes of a refused fit request (FitOptions::check).
#include <gtest/gtest.h>

#include <cmath>

#include "core/ident/fit_spec.h"

namespace flexarm {
namespace {

TEST(FitSpec, BlackBoxSpecsReadTheOrdersEachStructureTakes) {
  std::string why;
  const auto oe = fitModelSpecFromText("oe:2,3,1", false, &why);
  ASSERT_TRUE(oe) << why;
  EXPECT_EQ(oe->kind, FitModelKind::BlackBox);
  EXPECT_EQ(oe->structure, PolyStructure::Oe);
  EXPECT_EQ(oe->orders.nb, 2);
  EXPECT_EQ(oe->orders.nf, 3);
  EXPECT_EQ(oe->orders.nk, 1);
  EXPECT_EQ(oe->orders.na + oe->orders.nc + oe->orders.nd, 0);
  EXPECT_EQ(oe->name(), "oe[2 3 1]");
  EXPECT_EQ(fitModelSpecText(*oe), "oe:2,3,1");
  // The name a result prints reads back as the same spec, for every structure.
  for (const char* text : {"arx:4,4,1", "armax:2,3,2,1", "oe:2,3,1", "bj:2,2,3,4,1"}) {
    const auto s = fitModelSpecFromText(text, false, &why);
    ASSERT_TRUE(s) << text << ": " << why;
    EXPECT_EQ(fitModelSpecText(*s), text);
    const auto again = fitModelSpecFromText(s->name(), false, &why);
    ASSERT_TRUE(again) << s->name() << ": " << why;
    EXPECT_EQ(fitModelSpecText(*again), text);
  }
  EXPECT_EQ(polyOrdersOf(PolyStructure::Bj),
            (std::vector<PolyOrder>{PolyOrder::Nb, PolyOrder::Nc, PolyOrder::Nd, PolyOrder::Nf, PolyOrder::Nk}));
  EXPECT_TRUE(takesOrder(PolyStructure::Armax, PolyOrder::Nc));
  EXPECT_FALSE(takesOrder(PolyStructure::Oe, PolyOrder::Na));
  for (const char* bad : {"oe:2,2", "oe:2,x,1", "oe", "oe[2 2]", "arx:-1,2,1", "nosuch", "oe:2,2,1,1"})
    EXPECT_FALSE(fitModelSpecFromText(bad, false, &why)) << bad;
}

TEST(FitSpec, PhysicalAndNonparametricSpecs) {
  std::string why;
  const auto p = fitModelSpecFromText("two-mass", false, &why);
  ASSERT_TRUE(p) << why;
  EXPECT_EQ(p->kind, FitModelKind::Physical);
  ASSERT_TRUE(p->start);
  EXPECT_EQ(p->start->structureName(), "two-mass");
  EXPECT_EQ(p->start->value("J_a"), makeModel("two-mass")->value("J_a"));  // nominal, Table 5.2
  EXPECT_EQ(fitModelSpecText(*p), "two-mass");
  EXPECT_FALSE(fitModelSpecFromText("spa", false, &why));  // the fit keeps models only
  const auto spa = fitModelSpecFromText("spa:60", true, &why);
  ASSERT_TRUE(spa) << why;
  EXPECT_EQ(spa->kind, FitModelKind::Spa);
  EXPECT_EQ(spa->windowWidth, 60);
  EXPECT_EQ(fitModelSpecText(*spa), "spa:60");
  const auto etfe = fitModelSpecFromText("etfe", true, &why);
  ASSERT_TRUE(etfe) << why;
  EXPECT_EQ(etfe->windowWidth, 0);
  EXPECT_FALSE(fitModelSpecFromText("spa:-1", true, &why));
  EXPECT_FALSE(fitModelSpecFromText("spa:1,2", true, &why));
}

FitOptions physical(const char* structure) {
  std::string why;
  FitOptions o;
  o.model = *fitModelSpecFromText(structure, false, &why);
  return o;
}

TEST(FitSpec, ParameterOptionsNameModelAndEffectParameters) {
  FitOptions o = physical("three-mass");
  o.model.effects = {FitEffect::defaults(EffectKind::NonlinearSpring)};
  std::string why;
  ASSERT_TRUE(applyParameterOption(o, ParameterOption::Free, "J_m,beta", &why)) << why;
  EXPECT_EQ(freeParameterLabels(o.model), (std::vector<std::string>{"J_m", "beta (nonlinear_spring)"}));
  ASSERT_TRUE(applyParameterOption(o, ParameterOption::Fix, "J_m=1e-3", &why)) << why;
  ASSERT_TRUE(applyParameterOption(o, ParameterOption::Free, "J_m,J_a", &why)) << why;  // the last one wins
  EXPECT_EQ(freeParameterLabels(o.model), (std::vector<std::string>{"J_m", "J_a"}));
  ASSERT_EQ(o.startValues.size(), 1u);
  EXPECT_EQ(o.startValues[0].name, "J_m");
  EXPECT_EQ(o.startValues[0].value, 1e-3);
  ASSERT_TRUE(applyParameterOption(o, ParameterOption::Start, "beta=3e6", &why)) << why;
  EXPECT_EQ(o.model.effects[0].effect.values[0], 3e6);  // an effect's value is the effect's
  ASSERT_TRUE(applyParameterOption(o, ParameterOption::Bound, "d_g=-inf:inf", &why)) << why;
  ASSERT_EQ(o.bounds.size(), 1u);
  EXPECT_TRUE(std::isinf(o.bounds[0].lower));
  EXPECT_FALSE(applyParameterOption(o, ParameterOption::Start, "k_x=1", &why));
  EXPECT_NE(why.find("J_m, J_g, J_a"), std::string::npos) << why;  // says what there is
  EXPECT_FALSE(applyParameterOption(o, ParameterOption::Start, "J_m", &why));
  EXPECT_FALSE(applyParameterOption(o, ParameterOption::Bound, "J_m=5:1", &why));
  EXPECT_FALSE(applyParameterOption(o, ParameterOption::Fix, "beta=-1", &why));  // not physical
  EXPECT_EQ(o.model.effects[0].effect.values[0], 3e6);  // a refused option changes nothing

  FitModelSpec labelled = o.model;
  ASSERT_TRUE(setFreeParameters(labelled, {"beta (nonlinear_spring)", "k_g"}, &why)) << why;
  EXPECT_EQ(freeParameterLabels(labelled), (std::vector<std::string>{"k_g", "beta (nonlinear_spring)"}));
  EXPECT_FALSE(setFreeParameters(labelled, {"beta (backlash)"}, &why));

  FitOptions blackBox;
  EXPECT_FALSE(applyParameterOption(blackBox, ParameterOption::Free, "J_m", &why));
}

// What the command line used to check itself is the request's rule, with a code.
TEST(FitSpec, RefusedRequestsSayWhichRule) {
  auto withData = [](FitOptions o) {
    auto d = std::make_shared<IdData>();
    o.estimation = {{d, std::nullopt}};
    return o;
  };
  FitOptions bb;
  bb.model = *fitModelSpecFromText("oe:2,2,1", false, nullptr);
  bb = withData(bb);
  EXPECT_TRUE(bb.check().ok()) << bb.check().message;
  for (auto change : {+[](FitOptions& o) { o.randomStarts = 2; }, +[](FitOptions& o) { o.noiseModel = NoiseModel::Innovations; },
                      +[](FitOptions& o) { o.closedLoop = ClosedLoopChoice::Direct; },
                      +[](FitOptions& o) { o.startValues = {{"J_m", 1.0}}; },
                      +[](FitOptions& o) { o.model.armOutput = true; }}) {
    FitOptions o = bb;
    change(o);
    EXPECT_EQ(o.check().issue, FitIssue::PhysicalOnly) << o.check().message;
  }
  FitOptions p = withData(physical("two-mass"));
  EXPECT_TRUE(p.check().ok()) << p.check().message;
  p.closedLoop = ClosedLoopChoice::TwoStage;
  p.noiseModel = NoiseModel::Innovations;
  EXPECT_EQ(p.check().issue, FitIssue::ExcludesInnovations);
  p.noiseModel = NoiseModel::OutputError;
  p.closedLoop = ClosedLoopChoice::Indirect;
  p.decimation = 10;
  EXPECT_EQ(p.check().issue, FitIssue::IndirectExcludesDecimation);
  p.closedLoop = ClosedLoopChoice::Auto;
  p.maxIterations = 0;
  EXPECT_EQ(p.check().issue, FitIssue::OutOfRange);
  p.maxIterations = 10;
  p.method = FitMethod::Idim;
  EXPECT_EQ(p.check().issue, FitIssue::MethodExcludesDecimation);
  p.decimation = 1;
  p.bounds = {{"k_x", 0.0, 1.0}};
  EXPECT_EQ(p.check().issue, FitIssue::UnknownParameter);
  EXPECT_STREQ(toString(FitIssue::UnknownParameter), "unknown-parameter");
}

}  // namespace
}  // namespace flexarm
