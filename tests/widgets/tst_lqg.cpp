// The LQG panel (chapter 8): drags the R2 slider from the seed's case (i) 1e-6 to case (ii)
// 1e-8 with mouse and keyboard and checks that the badge flips to an unstable regulator with
// two right-half-plane poles (Section 8.3), that the pinned design stays overlaid, and that
// the Nyquist curve changes; plus presets, saturation and a model from the shared list.
#include <QApplication>
#include <QComboBox>
#include <QLineEdit>
#include <QMouseEvent>
#include <QPushButton>
#include <QSignalSpy>
#include <QScrollArea>
#include <QSlider>
#include <QStyle>
#include <QStyleOptionSlider>
#include <QtTest>
#include <qcustomplot.h>

#include "app/main_window.h"
#include "core/models/physical_models.h"
#include "widget_test_support.h"
#include "widgets/log_slider.h"
#include "widgets/lqg_panel.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {

// The slider's handle and groove as its style lays them out.
QRect sliderPart(QSlider* s, QStyle::SubControl part) {
  QStyleOptionSlider opt;
  opt.initFrom(s);
  opt.orientation = s->orientation();
  opt.minimum = s->minimum();
  opt.maximum = s->maximum();
  opt.sliderPosition = s->sliderPosition();
  opt.sliderValue = s->value();
  return s->style()->subControlRect(QStyle::CC_Slider, &opt, part, s);
}

// Pixel of a slider position along the groove.
int pixelOf(QSlider* s, int position) {
  const QRect handle = sliderPart(s, QStyle::SC_SliderHandle);
  const QRect groove = sliderPart(s, QStyle::SC_SliderGroove);
  const int span = groove.width() - handle.width();
  return groove.x() + handle.width() / 2 +
         QStyle::sliderPositionFromValue(s->minimum(), s->maximum(), position, span);
}

QPoint handleCentre(QSlider* s) { return sliderPart(s, QStyle::SC_SliderHandle).center(); }

int curvesOfColour(QCustomPlot* p, const QColor& c) {
  int n = 0;
  for (int i = 0; i < p->plottableCount(); ++i)
    if (auto* curve = qobject_cast<QCPCurve*>(p->plottable(i)))
      if (curve->pen().color() == c) ++n;
  return n;
}

const QColor kPinnedColour(255, 127, 14);

}  // namespace

class LqgPanelTest : public QObject {
  Q_OBJECT
 private:
  Workspace* workspace_ = nullptr;
  LqgPanel* panel_ = nullptr;

  void addModel(const char* structure) {
    ModelEntry e;
    e.name = structure;
    e.model = std::shared_ptr<PhysicalModel>(makeModel(structure));
    workspace_->addModel(e);
  }

 private slots:
  void initTestCase() {
    workspace_ = new Workspace;
    panel_ = new LqgPanel(workspace_);
    panel_->resize(1500, 1000);
    panel_->show();
    QVERIFY(QTest::qWaitForWindowExposed(panel_));
  }

  void opensWithCaseIStable() {
    // Section 8.3 case (i): Table 8.1, Q1 = diag(100, 1, 0, 0, 0), Q2 = 1,
    // R1 = diag(0, 0, 0, 0, 1), R2 = 1e-6 gives a stable regulator.
    const LqgOptions o = panel_->options();
    QCOMPARE(o.r2(0), 1e-6);
    QCOMPARE(o.q1(0), 100.0);
    QCOMPARE(o.r1(4), 1.0);
    QCOMPARE(o.parameters.k, 43.0);
    QTRY_VERIFY(panel_->current() != nullptr);
    QCOMPARE(panel_->badgeText(), QString("the regulator is stable"));
    QCOMPARE(panel_->current()->loop.encirclements, 0);
    QVERIFY2(panel_->summaryText().contains("encircles -1 0 times"),
             qPrintable(panel_->summaryText()));
  }

  void dragR2FlipsBadgeAndKeepsPinned() {
    auto* pinButton = panel_->findChild<QPushButton*>("pinButton");
    QVERIFY(pinButton);
    QTest::mouseClick(pinButton, Qt::LeftButton);
    QVERIFY(panel_->hasPinned());
    const LqgAnalysis* pinned = panel_->pinned();
    QVERIFY(panel_->pinnedBadgeText().contains("the regulator is stable"));
    QCOMPARE(curvesOfColour(panel_->nyquistPlot(), kPinnedColour), 1);
    QTest::qWait(50);
    const QString before = test::saveShot(panel_->grab().toImage(), "lqg_panel_case_i_pinned");
    const auto nyquistBefore = panel_->nyquistPoints();
    QVERIFY(nyquistBefore.size() > 100);

    LogSlider* r2 = panel_->weight("r2_1");
    QVERIFY(r2);
    QSlider* s = r2->slider();
    QCOMPARE(r2->value(), 1e-6);
    const int target = r2->positionOf(1e-8);
    QVERIFY(target < s->value());
    QSignalSpy analysed(panel_, &LqgPanel::analysed);
    // Drag the handle with the left button held, in small steps as a hand does.
    const QPoint start = handleCentre(s);
    const int dx = pixelOf(s, target) - pixelOf(s, s->value());
    QTest::mousePress(s, Qt::LeftButton, Qt::NoModifier, start);
    for (int i = 1; i <= 12; ++i) {
      const QPoint p = start + QPoint(dx * i / 12, 0);
      QMouseEvent move(QEvent::MouseMove, p, s->mapToGlobal(p), Qt::NoButton, Qt::LeftButton,
                       Qt::NoModifier);
      QApplication::sendEvent(s, &move);
      // Let each step's redesign show, whether it ran here or in the background.
      QTRY_VERIFY(!panel_->isComputing());
      QTest::qWait(5);
    }
    QTest::mouseRelease(s, Qt::LeftButton, Qt::NoModifier, start + QPoint(dx, 0));
    QVERIFY2(std::abs(s->value() - target) <= 3,
             qPrintable(QString("drag ended at %1, target %2").arg(s->value()).arg(target)));
    QVERIFY2(analysed.count() >= 6,  // the plots followed the drag, not only its end
             qPrintable(QString::number(analysed.count())));
    qInfo("%s", qPrintable(panel_->summaryText()));
    qInfo("slider move: %d updates during the drag, last one %.2f ms (redesign + plot data)",
          static_cast<int>(analysed.count()), panel_->lastUpdateSeconds() * 1e3);
    // Arrow keys for the last steps to exactly 1e-8.
    s->setFocus();
    for (int guard = 0; s->value() != target && guard < 10; ++guard)
      QTest::keyClick(s, s->value() > target ? Qt::Key_Left : Qt::Key_Right);
    QCOMPARE(s->value(), target);
    QCOMPARE(r2->value(), 1e-8);
    QCOMPARE(panel_->options().r2(0), 1e-8);
    QTRY_VERIFY(!panel_->isComputing());

    // Case (ii): unstable regulator with two RHP poles, F_y G encircles -1 twice (8.6).
    QTRY_COMPARE(panel_->badgeText(), QString("the regulator is unstable: 2 poles in the RHP"));
    QCOMPARE(panel_->current()->design.rhpRegulatorPoles, 2);
    QCOMPARE(panel_->current()->loop.encirclements, 2);
    // Bode's integral (8.37) against pi * sum Re(p_i).
    const LqgAnalysis* c = panel_->current();
    QVERIFY(c->bodePrediction > 0.0);
    QVERIFY(std::abs(c->bodeIntegral - c->bodePrediction) < 1e-3 * c->bodePrediction);
    // The pinned stable design stays, in the badge and in every plot.
    QCOMPARE(panel_->pinned(), pinned);
    QCOMPARE(panel_->pinned()->design.rhpRegulatorPoles, 0);
    QVERIFY(panel_->pinnedBadgeText().contains("the regulator is stable"));
    QCOMPARE(curvesOfColour(panel_->nyquistPlot(), kPinnedColour), 1);
    int pinnedGraphs = 0;
    for (QCustomPlot* p : {panel_->sensitivityPlot(), panel_->stepPlot()})
      for (int i = 0; i < p->graphCount(); ++i)
        if (p->graph(i)->pen().color() == kPinnedColour) ++pinnedGraphs;
    QCOMPARE(pinnedGraphs, 3);  // |S|, arm angle and torque (|T| is drawn in its own colour)
    // Figure 8.3: the unstable design rejects the arm-side step better.
    QVERIFY(c->steps.peakArmDeviation < pinned->steps.peakArmDeviation);
    // The Nyquist curve drawn is a different one.
    const auto nyquistAfter = panel_->nyquistPoints();
    QVERIFY(nyquistAfter.size() > 100);
    double change = 0.0;
    const std::size_t n = std::min(nyquistBefore.size(), nyquistAfter.size());
    for (std::size_t i = 0; i < n; ++i)
      change = std::max(change, std::abs(nyquistAfter[i] - nyquistBefore[i]));
    QVERIFY(nyquistAfter.size() != nyquistBefore.size() || change > 0.1);
    QTest::qWait(50);
    const QString after = test::saveShot(panel_->grab().toImage(), "lqg_panel_case_ii_vs_pinned");
    QVERIFY(QFile::exists(before) && QFile::exists(after));
  }

  void saturationDrawsDescribingFunctionLine() {
    auto* sat = panel_->findChild<QCheckBox*>("saturation");
    QVERIFY(sat);
    const int items = panel_->nyquistPlot()->itemCount();
    QTest::mouseClick(sat, Qt::LeftButton, Qt::NoModifier, QPoint(8, sat->height() / 2));
    QVERIFY(sat->isChecked());
    QTRY_VERIFY(!panel_->current()->saturated.time.empty());
    QVERIFY(panel_->nyquistPlot()->itemCount() > items);  // -1/Y_f line and its label
    QVERIFY2(panel_->summaryText().contains("anti-windup"), qPrintable(panel_->summaryText()));
    QTest::qWait(50);
    test::saveShot(panel_->grab().toImage(), "lqg_panel_saturation");
    QTest::mouseClick(sat, Qt::LeftButton, Qt::NoModifier, QPoint(8, sat->height() / 2));
    QTRY_VERIFY(panel_->current()->saturated.time.empty());
  }

  void accelerationPresetIsStableWithLowerSensitivity() {
    const double unstableMaxS = panel_->current()->maxSensitivity;
    QCOMPARE(panel_->current()->design.rhpRegulatorPoles, 2);
    QTest::mouseClick(panel_->findChild<QPushButton*>("preset_acceleration-feedback"),
                      Qt::LeftButton);
    QTRY_COMPARE(panel_->badgeText(), QString("the regulator is stable"));
    QCOMPARE(panel_->options().r2(1), 1e-1);
    QCOMPARE(panel_->current()->design.K.cols(), 2);
    // Section 8.7 / Figure 8.10: lower max |S| than the unstable case (ii).
    QVERIFY(panel_->current()->maxSensitivity < unstableMaxS);
    QTest::mouseClick(panel_->findChild<QPushButton*>("preset_case-i"), Qt::LeftButton);
    QTRY_COMPARE(panel_->current()->design.K.cols(), 1);
  }

  void badParameterIsRefusedAndModelIsReduced() {
    auto* k = panel_->findChild<QLineEdit*>("param_k");
    QVERIFY(k);
    k->selectAll();
    QTest::keyClicks(k, "-5");
    QTest::keyClick(k, Qt::Key_Return);
    QCOMPARE(panel_->options().parameters.k, 43.0);
    QVERIFY2(k->toolTip().contains("k must be positive"), qPrintable(k->toolTip()));
    // A two-mass model of the shared list (Table 5.2), chosen in the plant combo with the
    // keyboard, is scaled by the gear ratio.
    addModel("two-mass");
    auto* source = panel_->findChild<QComboBox*>("plantSource");
    QVERIFY(source);
    QCOMPARE(source->count(), 2);
    source->setFocus();
    QTest::keyClick(source, Qt::Key_Down);
    QCOMPARE(source->currentIndex(), 1);
    QTRY_VERIFY(!panel_->isComputing());  // slow machines redesign in the background
    QVERIFY2(panel_->reductionText().contains("scaled by r^2"), qPrintable(panel_->reductionText()));
    QVERIFY(std::abs(panel_->options().parameters.Ja - 12.0 / (118.0 * 118.0)) < 1e-12);
    QTRY_VERIFY(panel_->current()->ok());
    const double a21 = -1.5e5 / (118.0 * 118.0) / 9e-4;  // -k/J_m of (8.4), k = r^2 k_a
    QVERIFY(std::abs(panel_->current()->design.plant.A(1, 0) / a21 - 1.0) < 1e-12);
    // A rigid model cannot be reduced: a sentence, and the parameters stay.
    addModel("rigid");
    panel_->selectSource(2);
    QVERIFY2(panel_->reductionText().contains("no spring"), qPrintable(panel_->reductionText()));
    QVERIFY(std::abs(panel_->options().parameters.Ja - 12.0 / (118.0 * 118.0)) < 1e-12);
    // A three-mass model (Table 5.7 p6) matched at its first antiresonance and resonance.
    addModel("three-mass");
    panel_->selectSource(3);
    QTRY_VERIFY(!panel_->isComputing());
    QVERIFY2(panel_->reductionText().contains("first antiresonance"),
             qPrintable(panel_->reductionText()));
    const TwoMassLqgParameters p = panel_->options().parameters;
    QTRY_VERIFY(panel_->current()->ok());
    QVERIFY(p.Jm != 4.56e-4);  // the motor inertia absorbs part of the gear-side mass
    QTest::qWait(50);
    test::saveShot(panel_->grab().toImage(), "lqg_panel_three_mass");
    panel_->selectSource(0);
    QCOMPARE(panel_->options().parameters.Ja, 0.0762);
  }

  void slowUpdatesRunInTheBackgroundAndCoalesce() {
    // As if each redesign took longer than the budget: every update goes off the GUI thread
    // and key presses made meanwhile are coalesced into one more redesign.
    panel_->setSynchronousBudget(0.0);
    QSignalSpy analysed(panel_, &LqgPanel::analysed);
    QTest::mouseClick(panel_->findChild<QPushButton*>("preset_case-i"), Qt::LeftButton);
    QCOMPARE(analysed.count(), 0);  // not drawn within the click: the result comes back later
    QVERIFY(analysed.wait(10000));
    QTRY_VERIFY(!panel_->isComputing());
    QCOMPARE(panel_->badgeText(), QString("the regulator is stable"));
    analysed.clear();
    QSlider* s = panel_->weight("r2_1")->slider();
    const int target = panel_->weight("r2_1")->positionOf(1e-8);
    const int presses = s->value() - target;
    QVERIFY(presses >= 20);
    for (int i = 0; i < presses; ++i) QTest::keyClick(s, Qt::Key_Left);
    QCOMPARE(panel_->options().r2(0), 1e-8);
    QTRY_VERIFY(!panel_->isComputing() && analysed.count() > 0);
    QTest::qWait(20);
    QTRY_VERIFY(!panel_->isComputing());
    QVERIFY2(analysed.count() < presses, qPrintable(QString::number(analysed.count())));
    // The design shown is the one of the last setting.
    QCOMPARE(panel_->badgeText(), QString("the regulator is unstable: 2 poles in the RHP"));
    panel_->setSynchronousBudget(0.012);
  }

  void mainWindowHasTheLqgDock() {
    MainWindow w;
    QVERIFY(w.lqgPanel() != nullptr);
    QVERIFY(w.findChild<QDockWidget*>("lqgDock") != nullptr);
    // The dock does not force the window wider than the other panels do.
    const QSize lqg = w.lqgPanel()->minimumSizeHint();
    const QSize model = w.findChild<QWidget*>("modelPanel")->minimumSizeHint();
    qInfo("minimum sizes: LQG %dx%d, Model %dx%d", lqg.width(), lqg.height(), model.width(),
          model.height());
    QVERIFY(lqg.width() <= 700);
    // Its plots keep readable sizes; the dock scrolls them, so they never make the window
    // taller (tst_layout checks the window fits 1366x768).
    QVERIFY(qobject_cast<QScrollArea*>(w.findChild<QDockWidget*>("lqgDock")->widget()) != nullptr);
    // Docked and raised (a tab next to Preprocess and Model), showing the seed's case (i).
    w.resize(1400, 900);
    w.show();
    QVERIFY(QTest::qWaitForWindowExposed(&w));
    w.findChild<QDockWidget*>("lqgDock")->raise();
    QTRY_VERIFY(!w.lqgPanel()->visibleRegion().isEmpty());
    QCOMPARE(w.lqgPanel()->badgeText(), QString("the regulator is stable"));
    QTest::qWait(50);
    test::saveShot(w.grab().toImage(), "main_window_lqg_dock");
  }

  void cleanupTestCase() {
    delete panel_;
    delete workspace_;
  }
};

int main(int argc, char** argv) {
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName("FlexArmTests");
  LqgPanelTest t;
  return QTest::qExec(&t, argc, argv);
}

#include "tst_lqg.moc"
