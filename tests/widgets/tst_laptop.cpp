// The window as a new user meets it on a 1366x768 laptop, second pass (issue 31): every panel
// reached by name and brought to the front by its shortcut, the View menu and the panel
// switcher, a floated panel docked again in front, the layout chosen for the screen size, a
// range dragged where it was aimed, the wheel leaving unfocused controls alone, the Bode
// axes following what is shown, the arm flexing visibly at its default exaggeration, and
// report plots whose legends cover no data. Screenshots go to the build tree's screenshots/.
#include <QAction>
#include <QApplication>
#include <QDialog>
#include <QDockWidget>
#include <QLineEdit>
#include <QListWidget>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QSignalSpy>
#include <QSpinBox>
#include <QTableWidget>
#include <QWheelEvent>
#include <QtTest>
#include <cmath>
#include <qcustomplot.h>

#include "app/main_window.h"
#include "app/panel_docks.h"
#include "app/report_writer.h"
#include "core/session/report.h"
#include "widget_test_support.h"
#include "widgets/arm_panel.h"
#include "widgets/bode_panel.h"
#include "widgets/diagnosis_panel.h"
#include "widgets/log_panel.h"
#include "widgets/model_panel.h"
#include "widgets/plots/bode_plot.h"
#include "widgets/preprocess_panel.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {

const QString kSampleLog = QString(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
const QSize kLaptop(1366, 768 - 40), kDesktop(1920, 1080 - 40);

// Waits (handling events) until done() holds, at most 60 s.
template <class Done>
bool waitUntil(Done done) {
  for (int waited = 0; !done() && waited < 60000; waited += 20) QTest::qWait(20);
  return done();
}

// The dock can be seen: shown, docked, and not behind another tab.
bool inFront(const QDockWidget* d) { return d->isVisible() && !d->isFloating() && !d->visibleRegion().isEmpty(); }

// A second-order response with a deep notch: its band's lower bound reaches zero there.
BodeCurve notchCurve(const QString& name, double gain) {
  BodeCurve c;
  c.name = name;
  c.color = Qt::blue;
  for (int i = 0; i < 400; ++i) {
    const double w = std::pow(10.0, -1.0 + 4.0 * i / 399.0);
    const std::complex<double> s(0.0, w);
    const std::complex<double> h = gain * (s * s + 0.01 * s + 100.0) / ((s * s + 2.0 * s + 400.0) * (s + 1.0));
    c.frequency.push_back(w);
    c.response.push_back(h);
    const double m = std::abs(h);
    c.magnitudeLow.push_back(std::max(0.0, m - 0.02 * gain));  // zero near the notch
    c.magnitudeHigh.push_back(m + 0.02 * gain);
  }
  return c;
}

}  // namespace

class LaptopTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;

  QDockWidget* dock(const char* name) const { return window_->findChild<QDockWidget*>(name); }

  void showAt(QSize size) {
    window_->resize(size);
    QTest::qWait(50);
    QApplication::processEvents();
  }

 private slots:
  void initTestCase() {
    QSettings().clear();
    window_ = new MainWindow;
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    showAt(kLaptop);
    window_->docks()->arrange(PanelDocks::Layout::Compact);
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(kSampleLog);
    QVERIFY(opened.wait(30000));
  }

  // A laptop screen gets one tab group the whole height, the Arm view among the tabs; a large
  // screen keeps the Arm view below the tabs. Either way every panel is docked and shown.
  void layoutIsChosenForTheScreen() {
    QCOMPARE(PanelDocks::layoutFor(QSize(1366, 768)), PanelDocks::Layout::Compact);
    QCOMPARE(PanelDocks::layoutFor(QSize(1920, 1080)), PanelDocks::Layout::Wide);
    QDockWidget* arm = dock("armDock");
    QVERIFY(window_->tabifiedDockWidgets(arm).contains(dock("preprocessDock")));
    window_->docks()->showPanel(arm);
    QApplication::processEvents();
    QVERIFY2(arm->height() > 0.7 * window_->centralWidget()->height(),
             qPrintable(QString("Arm dock %1 px high beside a %2 px Log panel")
                            .arg(arm->height()).arg(window_->centralWidget()->height())));
    test::saveShot(window_->grab().toImage(), "laptop_compact_arm");
    showAt(kDesktop);
    window_->docks()->arrange(PanelDocks::Layout::Wide);
    QApplication::processEvents();
    QCOMPARE(window_->size(), kDesktop);  // arranging never grows the window
    QVERIFY(!window_->tabifiedDockWidgets(arm).contains(dock("preprocessDock")));
    QVERIFY2(arm->height() >= 300, qPrintable(QString::number(arm->height())));
    test::saveShot(window_->grab().toImage(), "laptop_wide_layout");
    showAt(kLaptop);
    window_->docks()->arrange(PanelDocks::Layout::Compact);
    QApplication::processEvents();
    QCOMPARE(window_->size(), kLaptop);
    for (const auto& p : window_->docks()->panels()) QVERIFY(!p.dock->isFloating() && !p.dock->isHidden());
    // The window can be made as narrow as the laptop's screen and narrower.
    QVERIFY2(window_->minimumSizeHint().width() <= 1100,
             qPrintable(QString::number(window_->minimumSizeHint().width())));
  }

  // Every panel's shortcut brings it to the front, whether it was behind another tab or
  // closed; its View menu entry never hides it.
  void everyPanelIsRaisedByItsShortcut() {
    window_->activateWindow();
    QVERIFY(QTest::qWaitForWindowActive(window_));
    const auto& panels = window_->docks()->panels();
    QVERIFY(panels.size() >= 11);
    for (std::size_t i = 0; i < panels.size(); ++i) {
      const auto& p = panels[i];
      window_->docks()->showPanel(panels[(i + 1) % panels.size()].dock);  // another in front
      QApplication::processEvents();
      QVERIFY2(!p.shortcut.isEmpty(), qPrintable(p.title));
      QTest::keySequence(window_, p.shortcut);
      QApplication::processEvents();
      QVERIFY2(inFront(p.dock), qPrintable(p.title + " not in front after " + p.shortcut.toString()));
      // Pressed again while in front, it stays.
      QTest::keySequence(window_, p.shortcut);
      QApplication::processEvents();
      QVERIFY2(inFront(p.dock), qPrintable(p.title + " hidden by its second " + p.shortcut.toString()));
    }
    // A closed panel comes back docked, in front.
    QDockWidget* recursive = dock("recursiveDock");
    recursive->close();
    QApplication::processEvents();
    QVERIFY(!recursive->isVisible());
    window_->findChild<QAction*>("recursiveDockAction")->trigger();
    QApplication::processEvents();
    QVERIFY(inFront(recursive));
  }

  // The switcher lists every panel; typing part of a name and Enter brings that one forward.
  void switcherFindsAPanelByName() {
    window_->docks()->showPanel(dock("preprocessDock"));
    window_->docks()->openSwitcher();
    QDialog* switcher = window_->docks()->switcher();
    QVERIFY(switcher->isVisible());
    auto* list = switcher->findChild<QListWidget*>("panelSwitcherList");
    QCOMPARE(list->count(), static_cast<int>(window_->docks()->panels().size()));
    auto* filter = switcher->findChild<QLineEdit*>("panelSwitcherFilter");
    QTest::keyClicks(filter, "diag");
    QTest::keyClick(filter, Qt::Key_Return);
    QApplication::processEvents();
    QVERIFY(!switcher->isVisible());
    QVERIFY(inFront(dock("diagnosisDock")));
    test::saveShot(window_->grab().toImage(), "laptop_switcher_diagnosis");
    // Its plots span the dock before any result (no empty legend row narrowing them).
    for (QCustomPlot* p : window_->diagnosisPanel()->findChildren<QCustomPlot*>())
      QVERIFY2(p->axisRect()->width() > p->width() / 2,
               qPrintable(QString("%1 of %2 px").arg(p->axisRect()->width()).arg(p->width())));
  }

  // A panel floated and docked again is the tab in front, not another one.
  void redockedPanelComesToTheFront() {
    QDockWidget* bode = dock("bodeDock");
    window_->docks()->showPanel(bode);
    bode->setFloating(true);
    QApplication::processEvents();
    window_->docks()->showPanel(dock("fitDock"));
    bode->setFloating(false);
    QTest::qWait(50);
    QVERIFY(inFront(bode));
    QVERIFY(!inFront(dock("fitDock")));
  }

  // Problem 5: a range dragged from 12.5 s to 17.5 s is 12.5-17.5 s within a pixel, however
  // long the readout under the plot grows while dragging.
  void rangeDragLandsWhereAimed() {
    LogPanel* log = window_->logPanel();
    log->showAll();
    log->setMode(LogPanel::Mode::SelectEstimation);
    QApplication::processEvents();
    QWidget* plot = log->plot();
    const int y = log->channelRect(0)->center().y();
    const QPoint from(qRound(log->pixelForTime(12.5)), y), to(qRound(log->pixelForTime(17.5)), y);
    const double perPixel = log->channelRect(0)->axis(QCPAxis::atBottom)->pixelToCoord(1.0) -
                            log->channelRect(0)->axis(QCPAxis::atBottom)->pixelToCoord(0.0);
    QTest::mousePress(plot, Qt::LeftButton, Qt::NoModifier, from);
    for (int step = 1; step <= 10; ++step) {
      test::moveMouse(plot, from + (to - from) * step / 10, Qt::LeftButton);
      QTest::qWait(10);  // the layout settles as a user's drag lets it
    }
    QTest::mouseRelease(plot, Qt::LeftButton, Qt::NoModifier, to);
    const auto r = window_->workspace()->range(RangeKind::Estimation);
    QVERIFY(r.has_value());
    const double slack = perPixel + window_->workspace()->current()->sampleTime;
    QVERIFY2(std::abs(r->start - 12.5) <= slack && std::abs(r->end - 17.5) <= slack,
             qPrintable(QString("%1-%2 s, a pixel is %3 s").arg(r->start).arg(r->end).arg(perPixel)));
    log->setMode(LogPanel::Mode::Navigate);
  }

  // Problem 6: the wheel over an unfocused spin box scrolls the panel and leaves the value;
  // once the box has the focus the wheel steps it.
  void wheelLeavesUnfocusedControls() {
    window_->docks()->showPanel(dock("preprocessDock"));
    QApplication::processEvents();
    auto* factor = window_->preprocessPanel()->findChild<QSpinBox*>("factorSpin");
    QVERIFY(factor);
    window_->logPanel()->plot()->setFocus();
    QApplication::processEvents();
    QVERIFY(!factor->hasFocus());
    const int before = factor->value();
    auto wheel = [factor] {
      const QPointF at(factor->width() / 2.0, factor->height() / 2.0);
      QWheelEvent e(at, factor->mapToGlobal(at), QPoint(), QPoint(0, -120), Qt::NoButton, Qt::NoModifier,
                    Qt::NoScrollPhase, false);
      QApplication::sendEvent(factor, &e);
      QApplication::processEvents();
    };
    wheel();
    QCOMPARE(factor->value(), before);
    factor->setFocus();
    QApplication::processEvents();
    wheel();
    QVERIFY(factor->value() != before);
    factor->setValue(before);
  }

  // Problem 7: the magnitude axis spans what is shown: not a band's dive to -6000 dB at a
  // notch, not a hidden curve; a curve hidden by the user stays hidden when drawn again.
  void bodeAxesFollowWhatIsShown() {
    BodePlot plot;
    plot.resize(600, 500);
    plot.addCurve(notchCurve("small", 1.0));
    const int big = plot.addCurve(notchCurve("large", 1e4));
    QCPAxis* mag = plot.magnitudeRect()->axis(QCPAxis::atLeft);
    QVERIFY2(mag->range().lower > -250.0, qPrintable(QString::number(mag->range().lower)));
    QVERIFY2(mag->range().upper > 40.0, qPrintable(QString::number(mag->range().upper)));
    plot.setCurveVisible(big, false);
    QVERIFY2(mag->range().upper < 0.0, qPrintable(QString::number(mag->range().upper)));
    QVERIFY2(mag->range().lower > -250.0, qPrintable(QString::number(mag->range().lower)));
    plot.clear();  // a refresh (SPA ticked) draws every curve again
    plot.addCurve(notchCurve("small", 1.0));
    QCOMPARE(plot.isCurveVisible(plot.addCurve(notchCurve("large", 1e4))), false);
    QVERIFY(mag->range().upper < 0.0);
    // In the panel: a model's curve hidden from its legend stays hidden when SPA is ticked.
    QVERIFY(window_->modelPanel()->newModel("three-mass") >= 0);
    BodePanel* bode = window_->bodePanel();
    QVERIFY(waitUntil([bode] { return !bode->isBusy() && bode->plot()->curveCount() >= 1; }));
    bode->plot()->setCurveVisible(0, false);
    bode->setNonparametricShown(true, false);
    QVERIFY(waitUntil([bode] { return !bode->isBusy() && bode->plot()->curveCount() >= 2; }));
    QVERIFY(!bode->plot()->isCurveVisible(0));
    QVERIFY(bode->plot()->isCurveVisible(1));  // SPA
    bode->setNonparametricShown(false, false);
  }

  // Problem 9: a report plot's legend sits outside the data and names each curve once (the
  // nameless second bound of a threshold has no entry).
  void reportLegendsCoverNoData() {
    ReportPlot p{"CUSUM", "time (s)", "g / h", false, false, {}};
    std::vector<double> t, a, b;
    for (int i = 0; i < 200; ++i) {
      t.push_back(0.1 * i);
      a.push_back(std::sin(0.1 * i));
      b.push_back(std::cos(0.1 * i));
    }
    p.series = {{"estimate", t, a}, {"smoothed", t, b}, {"threshold", t, std::vector<double>(t.size(), 0.9), true, 2},
                {"", t, std::vector<double>(t.size(), -0.9), true, 2}};
    auto plot = reportPlot(p);
    QCOMPARE(plot->legend->itemCount(), 3);
    QVERIFY(plot->legend->visible());
    plot->replot();
    const QRect legend = plot->legend->outerRect();
    const QRect data = plot->axisRect()->rect();
    QVERIFY2(!legend.intersects(data), qPrintable(QString("legend %1,%2 %3x%4 over data %5,%6 %7x%8")
                                                      .arg(legend.x()).arg(legend.y()).arg(legend.width())
                                                      .arg(legend.height()).arg(data.x()).arg(data.y())
                                                      .arg(data.width()).arg(data.height())));
    test::saveShot(plot->toPixmap(680, 300).toImage(), "laptop_report_legend");
  }

  void cleanupTestCase() {
    delete window_;
    QSettings().clear();
  }
};

int main(int argc, char** argv) { return test::runWidgetTest<LaptopTest>(argc, argv, "FlexArmLaptopTests"); }

#include "tst_laptop.moc"
