// The identification panels in the main window: opens the chirp sample log (three-mass truth,
// closed loop), sets estimation and validation ranges, clicks Estimate for a physical and a
// black-box model, and checks the results table, the shared model list, the Bode bands, the
// Compare fits, the residual tests, Cancel and the sensitivity study; screenshots of every
// panel.
#include <QApplication>
#include <QCheckBox>
#include <cmath>
#include <QComboBox>
#include <QDockWidget>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QPushButton>
#include <QSignalSpy>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QtTest>
#include <qcustomplot.h>

#include <nlohmann/json.hpp>
#include <sstream>

#include "app/cli/cli.h"
#include "app/main_window.h"
#include "app/session_controller.h"
#include "core/io/log_io.h"
#include "core/models/physical_models.h"
#include "core/session/fit_request.h"
#include "widget_test_support.h"
#include "widgets/arm/vtk_view.h"
#include "widgets/bode_panel.h"
#include "widgets/compare_panel.h"
#include "widgets/fit_panel.h"
#include "widgets/model_panel.h"
#include "widgets/plots/bode_plot.h"
#include "widgets/plots/pole_zero_plot.h"
#include "widgets/plots/transient_plot.h"
#include "widgets/residuals_panel.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {
const QString kSampleLog = QString(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";

// Waits until the panel's Estimate has finished and returns whether it succeeded.
bool clickEstimate(FitPanel* fit) {
  QSignalSpy done(fit, &FitPanel::estimated);
  QTest::mouseClick(fit->findChild<QPushButton*>("estimateButton"), Qt::LeftButton);
  if (!done.wait(120000)) return false;
  return done.takeFirst().at(0).toBool();
}
}  // namespace

class IdentificationTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;

  // The Bode, Compare and Residuals panels compute in the background: waits for them.
  void settle() { QTRY_VERIFY_WITH_TIMEOUT(!window_->isBusy(), 60000); }
  // The Compare panel in front, comparing on the validation range, its work done.
  void compareOnValidation() {
    showDock("compareDock");
    window_->comparePanel()->setRangeKind(RangeKind::Validation);
    settle();
  }

  void showDock(const char* name) {
    auto* dock = window_->findChild<QDockWidget*>(name);
    QVERIFY(dock);
    dock->show();
    dock->raise();
    QTest::qWait(150);
  }

 private slots:
  void initTestCase() {
    window_ = new MainWindow;
    window_->resize(1500, 1000);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(kSampleLog);
    QVERIFY(opened.wait(30000));
    // Estimation on the chirp's first 9 s, validation on the rest (a different part of the
    // sweep: lower frequencies).
    window_->workspace()->setRange(RangeKind::Estimation, {0.5, 9.0});
    window_->workspace()->setRange(RangeKind::Validation, {9.0, 17.5});
  }

  void physicalFitFillsTheTableAndJoinsTheList() {
    FitPanel* fit = window_->fitPanel();
    showDock("fitDock");
    QVERIFY(fit->setModelChoice("three-mass"));
    fit->setFreeParameters({"J_m", "J_a", "k_g", "k_a", "d_a"});
    fit->setDecimation(10);
    const std::size_t before = window_->workspace()->models().size();
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    QCOMPARE(window_->workspace()->models().size(), before + 1);
    QCOMPARE(fit->lastModelIndex(), static_cast<int>(before));
    const ModelEntry& e = window_->workspace()->models().back();
    QVERIFY(e.model != nullptr);
    QCOMPARE(e.covariance.rows(), 5);

    QTableWidget* t = fit->resultsTable();
    QCOMPARE(t->rowCount(), static_cast<int>(makeModel("three-mass")->parameters().size()));
    int freeRows = 0;
    for (int r = 0; r < t->rowCount(); ++r) {
      if (t->item(r, 2)->text() == "fixed") continue;
      ++freeRows;
      bool ok = false;
      const double v = t->item(r, 1)->text().toDouble(&ok);
      QVERIFY(ok);
      const double s = t->item(r, 2)->text().toDouble(&ok);
      QVERIFY2(ok && s > 0.0, qPrintable(t->item(r, 0)->text() + " std " + t->item(r, 2)->text()));
      const double lo = t->item(r, 3)->text().toDouble(), hi = t->item(r, 4)->text().toDouble();
      QVERIFY(lo < v && v < hi);
      QVERIFY(std::abs((hi - lo) / 2 - 2.576 * s) < 0.01 * s + 1e-12 * std::abs(v));
      // The inertias and springs stay within a factor of two of the truth (Table 5.7 p6).
      const std::string name = t->item(r, 0)->text().toStdString();
      if (name != "d_a") {
        const double truth = makeModel("three-mass")->value(name);
        QVERIFY2(v > 0.5 * truth && v < 2.0 * truth, qPrintable(QString::fromStdString(name)));
      }
    }
    QCOMPARE(freeRows, 5);
    const QString s = fit->summaryText();
    // Both fit percentages, named: the seed's (5.2) and MATLAB compare's NRMSE.
    QVERIFY2(s.contains("% NRMSE on the estimation data") && s.contains("% NRMSE on the validation data") &&
                 s.contains("% (5.2), "),
             qPrintable(s));
    QVERIFY2(s.contains("Notches: ") && s.contains("rad/s"), qPrintable(s));
    // The log has a reference channel and is decimated, so the indirect fit cannot run at the
    // controller's rate: Auto takes the two-stage closed-loop fit and says why.
    QVERIFY2(s.contains("two-stage closed-loop fit: the reference explains"), qPrintable(s));
    test::saveShot(fit->grab().toImage(), "fit_panel_three_mass");
    // Direct on request, and the combo is off for the innovations form (it needs output error).
    auto* combo = fit->findChild<QComboBox*>("closedLoopCombo");
    QVERIFY(combo && combo->isEnabled());
    fit->setNoiseModel(NoiseModel::Innovations);
    QVERIFY(!combo->isEnabled());
    fit->setNoiseModel(NoiseModel::OutputError);
    fit->setClosedLoopMethod(ClosedLoopChoice::Direct);
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    QVERIFY2(fit->summaryText().contains("direct fit of closed-loop data"),
             qPrintable(fit->summaryText()));
    // Indirect: the log's controller closed around the model. Decimated data cannot carry the
    // loop (a sentence says so); at the log's own rate every free truth lies in its interval.
    QVERIFY(combo->findData("indirect") >= 0);
    fit->setClosedLoopMethod(ClosedLoopChoice::Indirect);
    QCOMPARE(combo->currentData().toString(), QString("indirect"));
    QVERIFY(!clickEstimate(fit));
    QVERIFY2(fit->summaryText().contains("controller's rate"), qPrintable(fit->summaryText()));
    fit->setDecimation(1);
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    QVERIFY2(fit->summaryText().contains("indirect closed-loop fit"), qPrintable(fit->summaryText()));
    const auto truthModel = makeModel("three-mass");
    for (int r = 0; r < t->rowCount(); ++r) {
      if (t->item(r, 2)->text() == "fixed") continue;
      const double truth = truthModel->value(t->item(r, 0)->text().toStdString());
      const double lo = t->item(r, 3)->text().toDouble(), hi = t->item(r, 4)->text().toDouble();
      QVERIFY2(lo <= truth && truth <= hi,
               qPrintable(t->item(r, 0)->text() + QString(" [%1, %2] truth %3").arg(lo).arg(hi).arg(truth)));
    }
    test::saveShot(fit->grab().toImage(), "fit_panel_indirect");
    fit->setDecimation(10);
    fit->setClosedLoopMethod(ClosedLoopChoice::TwoStage);
  }

  // Issue 13's identity: one log and one model through the Fit panel, `flexarm fit` and
  // `flexarm run` of the session the window saves give the same numbers, bit for bit, because
  // all three run the one fit pipeline (core/ident/fit.h) on the same options.
  void panelCommandLineAndReplayGiveIdenticalNumbers() {
    FitPanel* fit = window_->fitPanel();
    QVERIFY(fit->setModelChoice("three-mass"));
    fit->setFreeParameters({"J_m", "J_a", "k_g", "k_a"});
    fit->setDecimation(1);
    fit->setNoiseModel(NoiseModel::OutputError);
    fit->setStarts(0);
    fit->setClosedLoopMethod(ClosedLoopChoice::Auto);
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    const ModelEntry panel = window_->workspace()->models().back();
    QVERIFY(panel.model != nullptr);
    QVERIFY2(fit->summaryText().contains("indirect closed-loop fit"), qPrintable(fit->summaryText()));

    std::ostringstream out, err;
    QCOMPARE(cli::runCommandLine({"fit", kSampleLog.toStdString(), "--model", "three-mass", "--free",
                                  "J_m,J_a,k_g,k_a", "--range", "0.5:9", "--validation-range", "9:17.5",
                                  "--json"},
                                 out, err),
             0);
    const auto line = nlohmann::json::parse(out.str());
    QCOMPARE(line["closed_loop_method"].get<std::string>(), std::string("indirect"));

    QTemporaryDir dir;
    const QString path = dir.filePath("identity.json");
    QString why;
    QVERIFY2(window_->sessionController()->save(path, &why), qPrintable(why));
    std::ostringstream rout, rerr;
    QCOMPARE(cli::runCommandLine({"run", path.toStdString(), "--json"}, rout, rerr), 0);
    const auto report = nlohmann::json::parse(rout.str());
    const nlohmann::json* replay = nullptr;
    for (const auto& section : report["sections"])
      if (section["title"] == "Fit " + panel.name) replay = &section["values"]["fit"];
    QVERIFY2(replay, rout.str().c_str());

    int free = 0;
    for (std::size_t i = 0; i < panel.model->parameters().size(); ++i) {
      const auto& p = panel.model->parameters()[i];
      QCOMPARE(line["parameters"][p.name].get<double>(), p.value);
      QCOMPARE((*replay)["parameters"][p.name].get<double>(), p.value);
      const auto at = std::find(panel.covarianceIndices.begin(), panel.covarianceIndices.end(), static_cast<int>(i));
      if (at == panel.covarianceIndices.end()) continue;
      const auto k = static_cast<Eigen::Index>(at - panel.covarianceIndices.begin());
      const double sd = std::sqrt(std::max(0.0, panel.covariance(k, k)));
      QCOMPARE(line["std"][p.name].get<double>(), sd);
      QCOMPARE((*replay)["std"][p.name].get<double>(), sd);
      ++free;
    }
    QCOMPARE(free, 4);
    QCOMPARE((*replay)["loss"].get<double>(), line["loss"].get<double>());
    QCOMPARE((*replay)["fit_percent"].get<double>(), line["fit_percent"].get<double>());
    QCOMPARE((*replay)["fit_percent_validation"].get<double>(), line["fit_percent_validation"].get<double>());
    QVERIFY((*replay)["notches_rad_s"] == line["notches_rad_s"]);
    const QString shown = QString::number(line["fit_percent_validation"].get<double>(), 'f', 1) + " %";
    QVERIFY2(fit->summaryText().contains(shown), qPrintable(shown + " not in " + fit->summaryText()));
    // One model, one number: the Compare panel gives the estimate the validation fit % the Fit
    // panel and the command line give (each computed by core, once).
    {
      compareOnValidation();
      ComparePanel* cmp = window_->comparePanel();
      const auto fits = cmp->fits();
      QCOMPARE(static_cast<int>(fits.size()), static_cast<int>(window_->workspace()->models().size()));
      QVERIFY2(std::abs(fits.back() - line["fit_percent_validation"].get<double>()) < 0.01,
               qPrintable(QString("Compare %1, fit %2: ").arg(fits.back()).arg(line["fit_percent_validation"].get<double>()) +
                          cmp->fitText()));
    }
    // As a user sees it on a 1366 x 768 screen.
    window_->resize(1366, 768);
    QTest::qWait(300);
    test::saveShot(window_->grab().toImage(), "fit_identity_1366x768");
    test::saveShot(fit->grab().toImage(), "fit_panel_identity");
    window_->resize(1500, 1000);
    QTest::qWait(100);
  }

  // Start values and bounds typed in the panel reach the pipeline: a bound below the truth's
  // J_m holds, and the note names the parameter and the bound; a malformed item is refused.
  void startValuesAndBoundsFromThePanel() {
    FitPanel* fit = window_->fitPanel();
    showDock("fitDock");
    QVERIFY(fit->setModelChoice("three-mass"));
    fit->setFreeParameters({"J_m", "J_a", "k_g", "k_a"});
    fit->setDecimation(10);
    fit->setClosedLoopMethod(ClosedLoopChoice::TwoStage);
    auto* edit = fit->findChild<QLineEdit*>("startsBoundsEdit");
    QVERIFY(edit && edit->isEnabled());
    edit->setText("J_a=1.5, J_m=1e-4:3e-4");
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    QTableWidget* t = fit->resultsTable();
    QCOMPARE(t->item(0, 0)->text(), QString("J_m"));
    QVERIFY2(std::abs(t->item(0, 1)->text().toDouble() - 3e-4) < 1e-9, qPrintable(t->item(0, 1)->text()));
    QVERIFY2(fit->summaryText().contains("Note: J_m sits on its upper bound 0.0003; the data would push it above"),
             qPrintable(fit->summaryText()));
    // Issue 31, problem 4: why the fit stopped is shown whole, not in a box to scroll.
    QApplication::processEvents();
    auto* summary = fit->findChild<QLabel*>("fitSummary");
    QVERIFY(summary && summary->wordWrap());
    QVERIFY2(summary->height() >= summary->heightForWidth(summary->width()),
             qPrintable(QString("%1 px of %2").arg(summary->height()).arg(summary->heightForWidth(summary->width()))));
    test::saveShot(fit->grab().toImage(), "fit_panel_bounds");
    edit->setText("J_m=abc");
    QSignalSpy refused(fit, &FitPanel::estimated);
    QTest::mouseClick(fit->findChild<QPushButton*>("estimateButton"), Qt::LeftButton);
    QCOMPARE(refused.count(), 1);  // refused at once, before any estimate runs
    QCOMPARE(refused.takeFirst().at(0).toBool(), false);
    QVERIFY2(fit->summaryText().contains("'J_m=abc' is neither a start value"), qPrintable(fit->summaryText()));
    edit->clear();
  }

  void blackBoxFitJoinsTheListToo() {
    FitPanel* fit = window_->fitPanel();
    QVERIFY(fit->setModelChoice("oe"));
    PolyOrders o;
    o.nb = 4;
    o.nf = 4;
    o.nk = 1;
    fit->setOrders(o);
    fit->setDecimation(10);
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    const ModelEntry& e = window_->workspace()->models().back();
    QVERIFY(e.model == nullptr);
    QVERIFY(e.polynomial != nullptr);
    QCOMPARE(e.polynomial->sampleTime, 0.005);
    QCOMPARE(fit->resultsTable()->rowCount(), 8);
    QVERIFY(fit->resultsTable()->item(0, 2)->text().toDouble() > 0.0);
    QVERIFY2(fit->summaryText().contains("oe[4 4 1]"), qPrintable(fit->summaryText()));
    // The study still has the physical estimate to work on.
    QVERIFY(fit->findChild<QPushButton*>("studyButton")->isEnabled());
    test::saveShot(fit->grab().toImage(), "fit_panel_oe");
    // The Model panel shows a black-box entry without offering physical edits.
    ModelPanel* mp = window_->modelPanel();
    mp->selectModel(static_cast<int>(window_->workspace()->models().size()) - 1);
    QCOMPARE(mp->findChild<QTableWidget*>("parameterTable")->rowCount(), 0);
    QVERIFY(!mp->findChild<QPushButton*>("simulateButton")->isEnabled());
    QVERIFY(!mp->setParameter("J_m", 1.0));
  }

  void bodeShowsBandsAndNonparametricPoints() {
    BodePanel* bode = window_->bodePanel();
    showDock("bodeDock");
    bode->setNonparametricShown(true, false);
    settle();
    const QStringList names = bode->curveNames();
    const int n = static_cast<int>(window_->workspace()->models().size());
    QCOMPARE(names.size(), n + 1);  // every model and SPA
    const int physical = n - 2;      // the three-mass estimate
    QVERIFY2(names[physical].contains("three-mass"), qPrintable(names.join(", ")));
    QVERIFY(bode->curveHasBand(physical));
    QVERIFY(bode->curveHasBand(n - 1));  // OE with its covariance
    QVERIFY(!bode->curveHasBand(n));     // SPA drawn as points
    QVERIFY2(bode->noteText().contains("closed loop"), qPrintable(bode->noteText()));
    // A band is drawn: some graph of the plot has a filled channel.
    int filled = 0;
    for (int i = 0; i < bode->plot()->plot()->graphCount(); ++i)
      filled += bode->plot()->plot()->graph(i)->channelFillGraph() != nullptr;
    QVERIFY(filled >= 4);  // magnitude and phase bands of two models
    test::saveShot(bode->grab().toImage(), "bode_panel");
    // Only the physical estimate: a lower level gives a narrower band.
    for (int i = 0; i < n; ++i) bode->setModelShown(i, i == physical);
    bode->setNonparametricShown(false, false);
    settle();
    QCOMPARE(bode->curveNames().size(), 1);
    test::saveShot(bode->grab().toImage(), "bode_panel_three_mass_99");
    auto bandArea = [bode] {
      double area = 0.0;
      QCustomPlot* p = bode->plot()->plot();
      for (int g = 0; g < p->graphCount(); ++g) {
        QCPGraph* hi = p->graph(g);
        if (!hi->channelFillGraph()) continue;
        for (int i = 0; i < hi->dataCount(); ++i)
          area += hi->data()->at(i)->value - hi->channelFillGraph()->data()->at(i)->value;
      }
      return area;
    };
    const double area99 = bandArea();
    bode->setLevel(0.5);
    settle();
    const double area50 = bandArea();
    QVERIFY2(area99 > 0.0 && area50 < 0.5 * area99,
             qPrintable(QString("band area %1 at 99 %, %2 at 50 %").arg(area99).arg(area50)));
    bode->setLevel(0.99);
    settle();
    QTemporaryDir dir;
    for (const char* ext : {"png", "pdf", "svg"}) {
      const QString path = dir.filePath(QString("bode.%1").arg(ext));
      QString why;
      QVERIFY2(bode->exportTo(path, &why), qPrintable(why));
      QVERIFY(QFileInfo(path).size() > 1000);
    }
    for (int i = 0; i < n; ++i) bode->setModelShown(i, true);
  }

  void bodeShowsStepAndImpulseWithBands() {
    BodePanel* bode = window_->bodePanel();
    showDock("bodeDock");
    const int n = static_cast<int>(window_->workspace()->models().size());
    for (int i = 0; i < n; ++i) bode->setModelShown(i, i >= n - 2);  // the three-mass and OE estimates
    bode->setView(1);
    settle();
    QCOMPARE(bode->curveNames().size(), 2);
    QVERIFY(bode->curveHasBand(0));
    QVERIFY(bode->curveHasBand(1));
    QVERIFY2(bode->noteText().contains("Step responses from rest"), qPrintable(bode->noteText()));
    QCustomPlot* p = bode->transientPlot()->customPlot();
    int filled = 0;
    for (int g = 0; g < p->graphCount(); ++g) filled += p->graph(g)->channelFillGraph() != nullptr;
    QCOMPARE(filled, 2);
    QVERIFY(p->isVisible());
    QVERIFY(!bode->plot()->isVisible());
    QVERIFY(!bode->findChild<QCheckBox*>("bodeSpaCheck")->isEnabled());
    test::saveShot(bode->grab().toImage(), "bode_panel_step");
    bode->setView(2);
    settle();
    QVERIFY2(bode->noteText().contains("a pulse of area 1"), qPrintable(bode->noteText()));
    QCOMPARE(bode->curveNames().size(), 2);
    test::saveShot(bode->grab().toImage(), "bode_panel_impulse");
    bode->setView(0);
    settle();
    QVERIFY(bode->plot()->isVisible());
    for (int i = 0; i < n; ++i) bode->setModelShown(i, true);
    // The Model panel draws the physical estimate's 99 % pole and zero regions.
    ModelPanel* mp = window_->modelPanel();
    mp->selectModel(n - 2);
    QVERIFY(mp->poleZero()->regionCount() >= 5);  // three-mass: five poles, four zeros
    test::saveShot(mp->grab().toImage(), "model_panel_regions");
  }

  void compareShowsFitOfEveryModel() {
    compareOnValidation();
    ComparePanel* cmp = window_->comparePanel();
    const auto fits = cmp->fits();
    QCOMPARE(static_cast<int>(fits.size()), static_cast<int>(window_->workspace()->models().size()));
    // The physical estimate simulates the validation part of the sweep well.
    QVERIFY2(fits[fits.size() - 2] > 60.0, qPrintable(cmp->fitText()));
    // The OE model is simulated at its own 200 Hz.
    QVERIFY2(fits.back() > 30.0, qPrintable(cmp->fitText()));
    QVERIFY2(cmp->fitText().contains("(at 200 Hz)"), qPrintable(cmp->fitText()));
    QVERIFY2(cmp->fitText().contains("validation"), qPrintable(cmp->fitText()));
    // Both fit percentages, named: the seed's (5.2) and MATLAB compare's NRMSE of the same errors.
    const auto nrmse = cmp->fitsNrmse();
    QCOMPARE(nrmse.size(), fits.size());
    for (std::size_t i = 0; i < fits.size(); ++i)
      QVERIFY2(std::abs(nrmse[i] - 100.0 * (1.0 - std::sqrt(1.0 - fits[i] / 100.0))) < 1e-9,
               qPrintable(cmp->fitText()));
    QVERIFY2(cmp->fitText().contains("% (5.2), ") && cmp->fitText().contains("% NRMSE"), qPrintable(cmp->fitText()));
    QCOMPARE(cmp->plot()->graphCount(), static_cast<int>(fits.size()) + 1);
    test::saveShot(cmp->grab().toImage(), "compare_panel");
  }

  void residualsShowCorrelationsWithBounds() {
    ResidualsPanel* res = window_->residualsPanel();
    showDock("residualsDock");
    res->setRangeKind(RangeKind::Validation);
    res->setMaxLag(30);
    res->selectModel(static_cast<int>(window_->workspace()->models().size()) - 1);
    settle();
    const ResidualAnalysis& a = res->analysis();
    QCOMPARE(static_cast<int>(a.lags.size()), 31);
    QCOMPARE(static_cast<int>(a.crossLags.size()), 61);
    QVERIFY(a.autocorrelationBound > 0.0);
    QCOMPARE(a.autocorrelation[0], 1.0);
    QVERIFY2(res->verdictText().contains("Whiteness"), qPrintable(res->verdictText()));
    test::saveShot(res->grab().toImage(), "residuals_panel");
  }

  void cancelStopsAnEstimate() {
    FitPanel* fit = window_->fitPanel();
    QVERIFY(fit->setModelChoice("three-mass"));
    fit->setFreeParameters({"J_m", "J_g", "J_a", "f_m", "k_g", "k_a", "d_g", "d_a"});
    fit->setDecimation(1);
    fit->setStarts(50);
    const std::size_t before = window_->workspace()->models().size();
    QSignalSpy done(fit, &FitPanel::estimated);
    QTest::mouseClick(fit->findChild<QPushButton*>("estimateButton"), Qt::LeftButton);
    QVERIFY(fit->isBusy());
    QVERIFY(fit->findChild<QPushButton*>("fitCancelButton")->isEnabled());
    QTest::mouseClick(fit->findChild<QPushButton*>("fitCancelButton"), Qt::LeftButton);
    QVERIFY(done.wait(60000));
    QCOMPARE(done.takeFirst().at(0).toBool(), false);
    QVERIFY2(fit->summaryText().startsWith("Cancelled"), qPrintable(fit->summaryText()));
    QCOMPARE(window_->workspace()->models().size(), before);
    fit->setStarts(0);
  }

  void sensitivityStudyReportsLimitsAndSuccessRate() {
    FitPanel* fit = window_->fitPanel();
    QVERIFY(fit->setModelChoice("three-mass"));
    fit->setFreeParameters({"J_m", "k_g"});
    fit->setDecimation(10);
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    QCOMPARE(fit->freeParameters(), QStringList({"J_m", "k_g"}));  // kept as the list grew
    fit->setStudyRuns(24);
    QSignalSpy done(fit, &FitPanel::studyFinished);
    QTest::mouseClick(fit->findChild<QPushButton*>("studyButton"), Qt::LeftButton);
    QVERIFY(done.wait(120000));
    QVERIFY2(done.takeFirst().at(0).toBool(), qPrintable(fit->studyText()));
    QCOMPARE(fit->studyTable()->rowCount(), 2);
    QVERIFY2(fit->studyText().contains("of 24 runs succeeded"), qPrintable(fit->studyText()));
    showDock("fitDock");
    test::saveShot(fit->grab().toImage(), "fit_panel_study");
    test::saveShot(window_->grab().toImage(), "main_window_identification");
  }

  // Effects in the Fit panel: checking one adds its parameters to the free list, the estimate
  // lists them with std devs and joins the model list with its effects; a list model brings
  // its own effects (e.g. discovery's augmented model) for the fit to refine.
  void effectsAreFittedWithTheModel() {
    FitPanel* fit = window_->fitPanel();
    showDock("fitDock");
    QVERIFY(fit->setModelChoice("three-mass"));
    auto* coulomb = fit->findChild<QCheckBox*>("effect_coulomb_friction_check");
    QVERIFY(coulomb && coulomb->isEnabled());
    coulomb->setChecked(true);
    QCOMPARE(fit->effects(), QStringList{"coulomb_friction"});
    auto* list = fit->findChild<QListWidget*>("freeParameterList");
    QVERIFY(!list->findItems("F_c (coulomb_friction)", Qt::MatchExactly).isEmpty());
    QCOMPARE(list->findItems("v_s (coulomb_friction)", Qt::MatchExactly).front()->checkState(), Qt::Unchecked);
    fit->setFreeParameters({"J_m", "J_a", "k_g", "k_a", "F_c (coulomb_friction)"});
    fit->setDecimation(10);
    fit->setClosedLoopMethod(ClosedLoopChoice::Auto);
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    QTableWidget* t = fit->resultsTable();
    QCOMPARE(t->rowCount(), static_cast<int>(makeModel("three-mass")->parameters().size()) + 2);
    bool found = false;
    for (int r = 0; r < t->rowCount(); ++r)
      if (t->item(r, 0)->text() == "F_c (coulomb_friction)") {
        found = true;
        QVERIFY2(t->item(r, 2)->text().toDouble() > 0.0, qPrintable(t->item(r, 2)->text()));
      }
    QVERIFY(found);
    QVERIFY2(fit->summaryText().contains("linear part"), qPrintable(fit->summaryText()));
    const ModelEntry& estimate = window_->workspace()->models().back();
    QCOMPARE(estimate.effects.size(), std::size_t{1});
    QCOMPARE(estimate.effects[0].kind, EffectKind::CoulombFriction);
    QVERIFY(estimate.fitRequest && estimate.fitRequest->options.model.effects.size() == 1);
    // The panel at the size of a small laptop screen.
    const QSize before = window_->size();
    window_->resize(1366, 768);
    QTest::qWait(200);
    test::saveShot(window_->grab().toImage(), "fit_panel_effects_1366x768");
    test::saveShot(fit->grab().toImage(), "fit_panel_effects");
    window_->resize(before);

    // A model of the list with its own effect: checked, its value the start.
    ModelEntry withBacklash;
    withBacklash.name = "two-mass with backlash";
    withBacklash.model = makeModel("two-mass");
    Effect b = Effect::withDefaults(EffectKind::Backlash);
    b.values[0] = 3e-4;
    withBacklash.effects = {b};
    const int at = window_->workspace()->addModel(withBacklash);
    QVERIFY(fit->setModelChoice(QString("list:%1").arg(at)));
    QCOMPARE(fit->effects(), QStringList{"backlash"});
    const auto items = list->findItems("b (backlash)", Qt::MatchExactly);
    QCOMPARE(items.size(), 1);
    QVERIFY(items.front()->toolTip().contains("0.0003"));
    coulomb->setChecked(false);
    QVERIFY(fit->setModelChoice("three-mass"));
    QVERIFY(fit->effects().isEmpty());
  }

  // A second estimation experiment typed in "More experiments" (the chirp log's second half,
  // read inside the background fit): the summary lists both experiments' fit % (5.2) and
  // NRMSE, equal to fitModel's on the same options, and the request keeps the experiment.
  void moreExperimentsListEachFitPercent() {
    FitPanel* fit = window_->fitPanel();
    showDock("fitDock");
    QVERIFY(fit->setModelChoice("oe"));
    PolyOrders q;
    q.nb = 2;
    q.nf = 2;
    q.nk = 1;
    fit->setOrders(q);
    fit->setDecimation(10);
    auto* edit = fit->findChild<QLineEdit*>("fitMoreExperimentsEdit");
    QVERIFY(edit && edit->isEnabled());
    QVERIFY(fit->findChild<QPushButton*>("fitMoreExperimentsBrowse"));
    edit->setText(kSampleLog + "@9:17.5");
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));

    FitOptions o;
    o.model.kind = FitModelKind::BlackBox;
    o.model.structure = PolyStructure::Oe;
    o.model.orders = q;
    o.model.orders.na = 0;
    o.decimation = 10;
    auto second = std::make_shared<const IdData>(readLog(kSampleLog.toStdString()).data);
    o.estimation = {{window_->workspace()->currentShared(), SecondsRange{0.5, 9.0}},
                    {second, SecondsRange{9.0, 17.5}}};
    o.validation = {{window_->workspace()->currentShared(), SecondsRange{9.0, 17.5}}};
    const FitResult direct = fitModel(o);
    QVERIFY2(direct.ok(), direct.message.c_str());
    QCOMPARE(direct.estimation.size(), std::size_t(2));
    const QString text = fit->summaryText();
    for (int i = 0; i < 2; ++i) {
      const FitValidation& e = direct.estimation[static_cast<std::size_t>(i)];
      QVERIFY(e.fitPercent && e.fitPercentNrmse);
      const QString shown = QString("fit %1 % (5.2), %2 % NRMSE.")
                                .arg(*e.fitPercent, 0, 'f', 1)
                                .arg(*e.fitPercentNrmse, 0, 'f', 1);
      const QString line = QString("Estimation experiment %1 (").arg(i + 1);
      const int at = text.indexOf(line);
      QVERIFY2(at >= 0, qPrintable(line + " not in " + text));
      QVERIFY2(text.mid(at, text.indexOf('\n', at) - at).endsWith(shown), qPrintable(shown + " not in " + text));
    }
    QVERIFY(std::abs(*direct.estimation[0].fitPercent - *direct.estimation[1].fitPercent) > 0.05);
    QVERIFY2(!text.contains("Estimation experiment 3"), qPrintable(text));
    const ModelEntry& entry = window_->workspace()->models().back();
    QVERIFY(entry.fitRequest);
    QCOMPARE(entry.fitRequest->experiments.size(), std::size_t(1));
    QCOMPARE(QString::fromStdString(entry.fitRequest->experiments[0].path), kSampleLog);
    QVERIFY(entry.fitRequest->experiments[0].range == (SecondsRange{9.0, 17.5}));
    window_->resize(1366, 768);
    QTest::qWait(300);
    test::saveShot(fit->grab().toImage(), "fit_panel_more_experiments");
    window_->resize(1500, 1000);
    // A malformed range is refused at once, before anything is read.
    edit->setText(kSampleLog + "@9:x");
    QSignalSpy refused(fit, &FitPanel::estimated);
    QTest::mouseClick(fit->findChild<QPushButton*>("estimateButton"), Qt::LeftButton);
    QCOMPARE(refused.count(), 1);
    QVERIFY2(fit->summaryText().startsWith("More experiments:"), qPrintable(fit->summaryText()));
    edit->clear();
  }

  // Last, so the list above keeps its order: a state-space fit with its order from the data.
  void stateSpaceFitSaysItsOrder() {
    FitPanel* fit = window_->fitPanel();
    QVERIFY(fit->setModelChoice("ss"));
    PolyOrders o;
    o.na = 0;
    fit->setOrders(o);
    fit->setDecimation(10);
    QVERIFY2(clickEstimate(fit), qPrintable(fit->summaryText()));
    const ModelEntry& e = window_->workspace()->models().back();
    QVERIFY(e.polynomial != nullptr);
    QCOMPARE(e.polynomial->structure, PolyStructure::Ss);
    QVERIFY(e.polynomial->orders.na >= 1);
    QVERIFY2(fit->summaryText().contains("least MDL"), qPrintable(fit->summaryText()));
    QVERIFY2(fit->summaryText().contains(QString("ss[%1]").arg(e.polynomial->orders.na)), qPrintable(fit->summaryText()));
    test::saveShot(window_->grab().toImage(), "fit_state_space_1366x768");
    test::saveShot(fit->grab().toImage(), "fit_panel_state_space");
    // Compare predicts it k steps ahead as MATLAB's compare(data, model, k) does; the legend
    // names the horizon and both fit percentages.
    ComparePanel* cmp = window_->comparePanel();
    const int n = static_cast<int>(window_->workspace()->models().size());
    for (int i = 0; i < n; ++i) cmp->setModelShown(i, i == n - 1);
    cmp->setHorizon(1);
    compareOnValidation();
    QCOMPARE(static_cast<int>(cmp->fits().size()), 1);
    const double oneStep = cmp->fits().front();
    QVERIFY2(oneStep > 95.0, qPrintable(cmp->fitText()));
    QStringList legend;
    for (int g = 0; g < cmp->plot()->graphCount(); ++g) legend << cmp->plot()->graph(g)->name();
    QVERIFY2(legend.join("|").contains("(1-step)") && legend.join("|").contains("% NRMSE"), qPrintable(legend.join("|")));
    test::saveShot(cmp->grab().toImage(), "compare_panel_one_step");
    cmp->setHorizon(50);
    settle();
    QVERIFY2(cmp->fits().front() < oneStep, qPrintable(cmp->fitText()));
    cmp->setHorizon(0);
    for (int i = 0; i < n; ++i) cmp->setModelShown(i, true);
    settle();
  }

  void cleanupTestCase() { delete window_; }
};

int main(int argc, char** argv) {
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName("FlexArmTests");
  IdentificationTest t;
  return QTest::qExec(&t, argc, argv);
}

#include "tst_identification.moc"
