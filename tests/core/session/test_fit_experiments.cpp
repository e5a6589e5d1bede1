// More experiments of a fit request (core/ident/fit_experiments.h): written FILE[@A:B] and
// "val: FILE[@A:B]", kept in the request's JSON (older requests without them still read),
// replayed by reading their logs into the same FitOptions `flexarm fit --log` fills, with
// each experiment's fit % (5.2) that of fitModel on those options; an unreadable file is a
// sentence naming it.
#include <gtest/gtest.h>

#include "core/ident/fit_experiments.h"
#include "core/io/log_io.h"
#include "core/session/fit_request.h"

using namespace flexarm;
using nlohmann::json;

namespace {

const std::string kChirp = std::string(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";

FitRequest oeRequest() {
  FitRequest r;
  r.name = "oe[2 2 1] estimate";
  r.options.model.kind = FitModelKind::BlackBox;
  r.options.model.structure = PolyStructure::Oe;
  r.options.model.orders.na = 0;
  r.options.model.orders.nb = 2;
  r.options.model.orders.nf = 2;
  r.options.model.orders.nk = 1;
  r.options.decimation = 10;
  r.estimation = SecondsRange{0.5, 9.0};
  r.validation = SecondsRange{9.0, 17.5};
  r.experiments = {{kChirp, SecondsRange{9.0, 17.5}, false}, {kChirp, SecondsRange{0.5, 9.0}, true}};
  return r;
}

}  // namespace

TEST(FitExperiments, ListTextRoundTripsAndMalformedRangesAreRefused) {
  std::string why;
  auto list = experimentListFromText("a.csv@1:2.5,  val: b.csv\n c.mat", &why);
  ASSERT_TRUE(list) << why;
  ASSERT_EQ(list->size(), 3u);
  EXPECT_EQ((*list)[0], (ExperimentSource{"a.csv", SecondsRange{1.0, 2.5}, false}));
  EXPECT_EQ((*list)[1], (ExperimentSource{"b.csv", std::nullopt, true}));
  EXPECT_EQ((*list)[2].path, "c.mat");
  auto again = experimentListFromText(experimentListText(*list), &why);
  ASSERT_TRUE(again) << why;
  EXPECT_EQ(*again, *list);
  EXPECT_FALSE(experimentListFromText("a.csv@2:1", &why));
  EXPECT_NE(why.find("2:1"), std::string::npos) << why;
  EXPECT_FALSE(experimentListFromText("@1:2", &why));
  EXPECT_NE(why.find("file name"), std::string::npos) << why;
}

TEST(FitRequest, MoreExperimentsRoundTripAndReplayAsTheFit) {
  const FitRequest r = oeRequest();
  std::string why;
  auto back = fitRequestFromJson(json::parse(fitRequestToJson(r).dump()), &why);
  ASSERT_TRUE(back) << why;
  EXPECT_EQ(back->experiments, r.experiments);
  // A request written before more experiments existed reads as none.
  json old = fitRequestToJson(r);
  old.erase("experiments");
  auto older = fitRequestFromJson(old, &why);
  ASSERT_TRUE(older) << why;
  EXPECT_TRUE(older->experiments.empty());
  json bad = fitRequestToJson(r);
  bad["experiments"][0]["log"] = 3;
  EXPECT_FALSE(fitRequestFromJson(bad, &why));
  EXPECT_NE(why.find("\"log\""), std::string::npos) << why;

  LogReadResult read = readLog(kChirp);
  ASSERT_TRUE(read.ok);
  const IdData& data = read.data;
  const FitResult replayed = runFitRequest(*back, data);
  ASSERT_TRUE(replayed.ok()) << replayed.message;
  ASSERT_EQ(replayed.estimation.size(), 2u);
  ASSERT_EQ(replayed.validation.size(), 2u);
  // The same experiments built by hand: the open log's ranges, then the file's, read once.
  const std::shared_ptr<const IdData> view(&data, [](const IdData*) {});
  auto other = std::make_shared<const IdData>(readLog(kChirp).data);
  FitOptions o = r.options;
  o.estimation = {{view, SecondsRange{0.5, 9.0}}, {other, SecondsRange{9.0, 17.5}}};
  o.validation = {{view, SecondsRange{9.0, 17.5}}, {other, SecondsRange{0.5, 9.0}}};
  const FitResult direct = fitModel(o);
  ASSERT_TRUE(direct.ok()) << direct.message;
  for (std::size_t i = 0; i < 2; ++i) {
    ASSERT_TRUE(direct.estimation[i].fitPercent && direct.validation[i].fitPercent);
    EXPECT_EQ(replayed.estimation[i].fitPercent, direct.estimation[i].fitPercent) << i;
    EXPECT_EQ(replayed.estimation[i].fitPercentNrmse, direct.estimation[i].fitPercentNrmse) << i;
    EXPECT_EQ(replayed.validation[i].fitPercent, direct.validation[i].fitPercent) << i;
  }
  // The second estimation experiment is another part of the sweep: its fit % differs.
  EXPECT_NE(*direct.estimation[0].fitPercent, *direct.estimation[1].fitPercent);

  FitRequest missing = r;
  missing.experiments = {{"no/such/log.csv", std::nullopt, false}};
  const FitResult failed = runFitRequest(missing, data);
  EXPECT_FALSE(failed.ok());
  EXPECT_EQ(failed.status, FitStatus::BadData);
  EXPECT_NE(failed.message.find("no/such/log.csv"), std::string::npos) << failed.message;
}
