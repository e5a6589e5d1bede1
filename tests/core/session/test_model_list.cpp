// The model list without Qt (core/session/model_list.h): names stay unique, an estimate says
// where it came from, and a session's list is read the same way by every front end.
#include <gtest/gtest.h>

#include "core/session/fit_request.h"
#include "core/session/model_json.h"
#include "core/session/model_list.h"
#include "core/session/session_models.h"

namespace flexarm {
namespace {

ModelEntry handMade(const std::string& name, const std::string& structure = "two-mass") {
  ModelEntry e;
  e.name = name;
  e.model = std::shared_ptr<const PhysicalModel>(makeModel(structure));
  return e;
}

TEST(ModelList, NamesStayUnique) {
  ModelList list;
  EXPECT_EQ(list.uniqueName("two-mass"), "two-mass");
  EXPECT_EQ(list.insert(0, handMade("two-mass")), "two-mass");
  EXPECT_EQ(list.insert(1, handMade("two-mass")), "two-mass (2)");
  EXPECT_EQ(list.insert(2, handMade("two-mass")), "two-mass (3)");
  list.remove(1);
  EXPECT_EQ(list.uniqueName("two-mass"), "two-mass (2)");
  // Replacing an entry by one named as another renames it; keeping its own name does not.
  EXPECT_EQ(list.replace(1, handMade("two-mass (3)")), "two-mass (3)");
  EXPECT_EQ(list.replace(1, handMade("two-mass")), "two-mass (2)");
  EXPECT_EQ(list.indexOf("two-mass (2)"), 1);
  EXPECT_THROW(list.remove(5), std::out_of_range);
  Provenance p;
  p.log = "chirp.csv";
  p.estimation = SecondsRange{0.5, 12.0};
  EXPECT_EQ(list.resultName("three-mass estimate", p), "three-mass estimate (chirp.csv 0.5-12 s)");
}

TEST(ModelList, AnEstimateSaysWhichDataRangeRateAndEffects) {
  ModelEntry e = handMade("friction");
  EXPECT_EQ(e.provenanceText(), "by hand");
  e.effects = {Effect::withDefaults(EffectKind::CoulombFriction)};
  auto request = std::make_shared<FitRequest>();
  request->options.decimation = 10;
  Provenance p;
  p.log = "chirp.csv";
  p.sha256 = "ab";
  p.estimation = SecondsRange{0.5, 9.0};
  request->provenance = p;
  e.fitRequest = request;
  EXPECT_EQ(e.provenanceText(), "fit on chirp.csv 0.5-9 s at decimation 10, with coulomb_friction");
  const EvaluatedModel m = e.evaluated();
  EXPECT_EQ(m.decimation, 10);
  EXPECT_TRUE(m.nonlinear());
  // Estimated on other data than the open ones: listed with the difference.
  ModelList list;
  list.insert(0, e);
  list.insert(1, handMade("two-mass"));
  Provenance open = p;
  open.sha256 = "cd";
  const auto other = list.estimatedOnOtherData(open);
  ASSERT_EQ(other.size(), 1u);
  EXPECT_EQ(other.front().first, 0u);
  EXPECT_FALSE(other.front().second.empty());
  EXPECT_TRUE(list.estimatedOnOtherData(p).empty());
}

TEST(SessionModels, TheListWithItsFitsRequestsAndEstimates) {
  Session s;
  s.parts["models"] = nlohmann::json::array({modelToJson("three-mass estimate", *makeModel("three-mass"), {}),
                                             modelToJson("hand", *makeModel("two-mass"), {})});
  FitRequest physicalFit;
  physicalFit.name = "three-mass estimate";
  physicalFit.options.model.kind = FitModelKind::Physical;
  physicalFit.options.model.start = std::shared_ptr<const PhysicalModel>(makeModel("three-mass"));
  physicalFit.options.decimation = 10;
  s.parts["fits"] = {{"nonparametric", false}, {"requests", nlohmann::json::array({fitRequestToJson(physicalFit)})}};
  const ModelList list = modelListOf(s);
  ASSERT_EQ(list.size(), 2u);
  EXPECT_EQ(list[0].origin, ModelOrigin::Fit);
  ASSERT_TRUE(list[0].fitRequest);
  EXPECT_EQ(list[0].evaluated().decimation, 10);
  EXPECT_EQ(list[1].origin, ModelOrigin::Session);
  EXPECT_EQ(list[1].evaluated().decimation, 1);
}

}  // namespace
}  // namespace flexarm
