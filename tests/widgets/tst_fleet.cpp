// The Fleet dock in the main window at 1366x768, as a plant engineer uses it: a store of four
// axes over 24 days (one wearing, one whose k_T stepped up on day 14, two healthy through the
// cell's temperature swings) opens into a grid with each parameter's colour, sorts by status,
// shows a trend with its band, temperature, threshold and predicted crossing, and a click on
// a faulty day opens that day's log with its diagnosis in the Diagnosis dock, naming k_T.
#include <QComboBox>
#include <QDockWidget>
#include <QHeaderView>
#include <QSignalSpy>
#include <QTableWidget>
#include <QtTest>
#include <cmath>
#include <filesystem>
#include <unistd.h>
#include <qcustomplot.h>

#include "app/main_window.h"
#include "core/fleet/store.h"
#include "core/session/sha256.h"
#include "core/sim/random.h"
#include "widget_test_support.h"
#include "widgets/diagnosis_panel.h"
#include "widgets/fleet_panel.h"

using namespace flexarm;

namespace {
const QString kFaultyLog = QString(FLEXARM_SAMPLE_DIR) + "/diagnosis_fault_k_T.csv";
const QString kHealthyLog = QString(FLEXARM_SAMPLE_DIR) + "/diagnosis_step_none.csv";
const QString kReference = QString(FLEXARM_SAMPLE_DIR) + "/diagnosis_no_fault.csv";

// Writes the store: the estimates as the fleet's analysis gives them (scatter k_T 0.2 %,
// J_a 0.2 %, f_m 1.6 %, f_m following the temperature at 1.2 %/degC).
std::string makeStore() {
  const auto path = std::filesystem::temp_directory_path() / ("flexarm_tst_fleet_" + std::to_string(::getpid()) + ".sqlite");
  for (const char* tail : {"", "-wal", "-shm", ".writer"}) std::filesystem::remove(path.string() + tail);
  std::string why;
  auto store = FleetStore::open(path.string(), true, &why);
  if (!store) qFatal("%s", why.c_str());
  Random rng(5);
  struct Axis { const char* robot; int axis; const char* change; };
  const Axis axes[] = {{"R01", 1, ""}, {"R01", 2, "wear"}, {"R02", 1, "k_T"}, {"R02", 2, ""}};
  std::vector<StoredLog> logs;
  for (const auto& a : axes) {
    // Checksums as the store takes them: 64 hex digits.
    const std::string ref = sha256Hex(std::string(a.robot) + std::to_string(a.axis) + "-ref");
    store->putAxis({a.robot, a.axis, ref, kReference.toStdString(), 24.0, "{}"}, &why);
    for (int d = 0; d < 24; ++d) {
      const double T = 24.0 + 9.0 * std::sin(2.0 * M_PI * (d + a.axis) / 7.0) + 0.5 * rng.normal();
      StoredLog l;
      l.robot = a.robot;
      l.axis = a.axis;
      l.day = 20513.25 + d;
      l.time = isoFromDay(l.day);
      l.temperatureC = d == 0 ? 24.0 : T;
      const bool faulty = std::string(a.change) == "k_T" && d >= 14;
      l.path = (faulty ? kFaultyLog : kHealthyLog).toStdString();
      l.result.sha256 = sha256Hex(ref + "-" + std::to_string(d));
      l.result.referenceSha256 = ref;
      l.result.ok = true;
      l.result.verdict = faulty ? "k_T" : "none";
      const double wear = std::string(a.change) == "wear" && d > 9 ? 0.02 * (d - 9) : 0.0;
      const double fm = 0.0355 * (1.0 + 0.012 * (*l.temperatureC - 24.0)) * (1.0 + wear) * (1.0 + 0.016 * rng.normal());
      l.result.estimates = {{"k_T", (faulty ? 1.2 : 1.0) * (1.0 + 0.002 * rng.normal()), 0.002, 1.0},
                            {"J_a", 1.72 * (1.0 + 0.002 * rng.normal()), 0.0035, 1.72},
                            {"f_m", fm, 0.0006, 0.0355}};
      logs.push_back(l);
    }
  }
  if (!store->putLogs(logs, 1, &why)) qFatal("%s", why.c_str());
  store->setMeta("model", "three-mass", &why);
  return path.string();
}
}  // namespace

class FleetPanelTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;
  FleetPanel* panel_ = nullptr;
  std::string store_;

  int rowOf(const QString& robot, int axis) const {
    QTableWidget* g = panel_->grid();
    for (int r = 0; r < g->rowCount(); ++r)
      if (g->item(r, 0)->text() == robot && g->item(r, 1)->text() == QString::number(axis)) return r;
    return -1;
  }

 private slots:
  void initTestCase() {
    store_ = makeStore();
    window_ = new MainWindow;
    window_->resize(1366, 768);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    auto* dock = window_->findChild<QDockWidget*>("fleetDock");
    QVERIFY(dock != nullptr);
    dock->show();
    dock->raise();
    panel_ = window_->findChild<FleetPanel*>("fleetPanel");
    QVERIFY(panel_ != nullptr);
  }

  void gridShowsEachAxisAndParameterInColour() {
    QVERIFY(panel_->openStore(QString::fromStdString(store_)));
    QTableWidget* g = panel_->grid();
    QCOMPARE(g->rowCount(), 4);
    const int wear = rowOf("R01", 2), fault = rowOf("R02", 1), healthy = rowOf("R02", 2);
    QVERIFY(wear >= 0 && fault >= 0 && healthy >= 0);
    QCOMPARE(g->item(wear, 2)->text(), QString("drift f_m"));
    QCOMPARE(g->item(fault, 2)->text(), QString("fault k_T"));
    QCOMPARE(g->item(healthy, 2)->text(), QString("healthy"));
    QCOMPARE(g->item(rowOf("R01", 1), 2)->text(), QString("healthy"));
    // Colours: the wearing axis' f_m orange, the faulty axis' k_T red, the rest green.
    QCOMPARE(g->item(wear, 5)->background().color(), QColor(255, 204, 128));
    QCOMPARE(g->item(fault, 3)->background().color(), QColor(239, 154, 154));
    QCOMPARE(g->item(fault, 5)->background().color(), QColor(200, 230, 201));
    QVERIFY2(g->item(fault, 3)->text().startsWith("+20"), qPrintable(g->item(fault, 3)->text()));
    // A fault has passed the threshold already; a healthy axis foresees no crossing.
    QCOMPARE(g->item(fault, 7)->text(), QString("passed"));
    QCOMPARE(g->item(healthy, 7)->text(), QString("-"));
    // Sorted by status, the fault comes first, then the drift.
    g->sortByColumn(2, Qt::DescendingOrder);
    QCOMPARE(g->item(0, 2)->text(), QString("fault k_T"));
    QCOMPARE(g->item(1, 2)->text(), QString("drift f_m"));
  }

  void trendShowsBandTemperatureThresholdAndCrossing() {
    QTableWidget* g = panel_->grid();
    g->selectRow(rowOf("R01", 2));
    QTest::qWait(50);
    QCOMPARE(panel_->parameterBox()->currentText(), QString("f_m"));
    QCustomPlot* p = panel_->trendPlot();
    QStringList names;
    for (int i = 0; i < p->graphCount(); ++i) names << p->graph(i)->name();
    QVERIFY2(names.contains("estimate") && names.contains("+-2 std") && names.contains("fitted drift") &&
                 names.contains("temperature") && names.contains("predicted"),
             qPrintable(names.join(", ")));
    bool threshold = false, crossing = false;
    for (const auto& n : names) {
      threshold = threshold || n.startsWith("threshold +20");
      crossing = crossing || n.startsWith("crossing 2026-");
    }
    QVERIFY2(threshold && crossing, qPrintable(names.join(", ")));
    QCOMPARE(p->graph(0)->dataCount(), 24);
    QVERIFY2(panel_->evidenceText().contains("has risen"), qPrintable(panel_->evidenceText()));
    test::saveShot(window_->grab().toImage(), "fleet_window_wear");
    test::saveShot(panel_->grab().toImage(), "fleet_panel_wear");
  }

  void clickOnADayOpensItsLogWithItsDiagnosis() {
    panel_->grid()->selectRow(rowOf("R02", 1));
    QTest::qWait(50);
    QCOMPARE(panel_->parameterBox()->currentText(), QString("k_T"));
    QCustomPlot* p = panel_->trendPlot();
    p->replot();
    // Day 20 of the axis: after the step.
    const QPoint at(static_cast<int>(p->xAxis->coordToPixel(20.0)), static_cast<int>(p->yAxis->coordToPixel(20.0)));
    QSignalSpy requested(panel_, &FleetPanel::logRequested);
    QSignalSpy opened(window_, &MainWindow::logOpened);
    auto* diagnosis = window_->findChild<DiagnosisPanel*>();
    QVERIFY(diagnosis != nullptr);
    QSignalSpy done(diagnosis, &DiagnosisPanel::finished);
    QTest::mouseClick(p, Qt::LeftButton, Qt::NoModifier, at);
    QCOMPARE(requested.count(), 1);
    QCOMPARE(requested.at(0).at(0).toString(), kFaultyLog);
    QCOMPARE(requested.at(0).at(1).toString(), kReference);
    QVERIFY(opened.wait(30000));
    QVERIFY(done.count() > 0 || done.wait(240000));
    QCOMPARE(diagnosis->referenceLogPath(), kReference);
    QVERIFY(diagnosis->lastRun() && diagnosis->lastRun()->ok());
    QCOMPARE(QString::fromStdString(diagnosis->lastRun()->result.verdictName()), QString("k_T"));
    // Shown whole: the playhead went to the log's end, the verdict is on the panel.
    QTest::qWait(200);
    QVERIFY2(diagnosis->verdictText().contains("k_T"), qPrintable(diagnosis->verdictText()));
    test::saveShot(window_->grab().toImage(), "fleet_click_diagnosis");
  }

  void cleanupTestCase() {
    delete window_;
    for (const char* tail : {"", "-wal", "-shm", ".writer"}) std::filesystem::remove(store_ + tail);
  }
};

QTEST_MAIN(FleetPanelTest)
#include "tst_fleet.moc"
