// The window's playhead: what it does on its own (clamping, steps, speed, loop over a
// selection, a panel holding it), and in the window: one time moves the Log panel's line,
// Compare's line and the Arm view; a click in a time plot, the transport bar and the keys
// (Space, arrows) move it.
#include <QApplication>
#include <QKeyEvent>
#include <QSignalSpy>
#include <QSlider>
#include <QtTest>
#include <qcustomplot.h>

#include "app/main_window.h"
#include "widget_test_support.h"
#include "widgets/arm/arm_scene.h"
#include "widgets/arm/vtk_view.h"
#include "widgets/arm_panel.h"
#include "widgets/compare_panel.h"
#include "widgets/log_panel.h"
#include "widgets/playhead.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/transport_bar.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {
const QString kSampleLog = QString(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
}

class PlayheadTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;

  static void click(QWidget* w, QPoint p) {
    QTest::mousePress(w, Qt::LeftButton, Qt::NoModifier, p);
    QTest::mouseRelease(w, Qt::LeftButton, Qt::NoModifier, p);
  }
  void key(int k, Qt::KeyboardModifiers mods = Qt::NoModifier) {
    QKeyEvent e(QEvent::KeyPress, k, mods);
    QApplication::sendEvent(window_, &e);
  }

 private slots:
  void clampsStepsAndSpeed() {
    Playhead p;
    QSignalSpy moved(&p, &Playhead::timeChanged);
    p.setTime(3.0);  // no span: nothing to move
    QCOMPARE(moved.count(), 0);
    p.setSpan(1.0, 11.0, 0.001);
    QCOMPARE(p.time(), 1.0);
    p.setTime(20.0);
    QCOMPARE(p.time(), 11.0);
    p.setTime(-5.0);
    QCOMPARE(p.time(), 1.0);
    p.setTime(5.0);
    p.stepSamples(3);
    QVERIFY(std::abs(p.time() - 5.003) < 1e-12);
    p.stepSeconds(-2.0);
    QVERIFY(std::abs(p.time() - 3.003) < 1e-12);
    // A frame is what playing advances in one frame at the speed, never less than a sample.
    p.setSpeed(10.0);
    const double before = p.time();
    p.stepFrames(1);
    QVERIFY(std::abs(p.time() - before - 10.0 * p.frameIntervalMs() / 1000.0) < 1e-12);
    p.setSpeed(1000.0);
    QCOMPARE(p.speed(), Playhead::kMaxSpeed);
    p.setSpeed(0.001);
    QCOMPARE(p.speed(), Playhead::kMinSpeed);
    p.stepFrames(-1);  // 1.6 ms at x0.1: one frame is still more than a sample here
    QVERIFY(p.time() < before + 10.0 * p.frameIntervalMs() / 1000.0);
  }

  void playsAndStopsAtTheEnd() {
    Playhead p;
    p.setSpan(0.0, 0.3, 0.001);
    p.setSpeed(2.0);
    QSignalSpy playing(&p, &Playhead::playingChanged);
    p.play();
    QVERIFY(p.isPlaying());
    // 0.3 s of log at x2 takes 0.15 s: playing stops at the end by itself.
    QTRY_VERIFY_WITH_TIMEOUT(!p.isPlaying(), 5000);
    QCOMPARE(p.time(), 0.3);
    QCOMPARE(playing.count(), 2);
    // Play at the end starts again from the beginning.
    QSignalSpy moved(&p, &Playhead::timeChanged);
    p.play();
    QVERIFY(moved.count() >= 1);
    QCOMPARE(moved.first().at(0).toDouble(), 0.0);
    p.pause();
  }

  void loopsOverTheSelection() {
    Playhead p;
    p.setSpan(0.0, 10.0, 0.0005);
    p.setSelection(4.0, 2.0);  // given backwards
    QCOMPARE(p.selection()->first, 2.0);
    QCOMPARE(p.selection()->second, 4.0);
    p.setLooping(true);
    p.setSpeed(20.0);
    QVector<double> seen;
    connect(&p, &Playhead::timeChanged, &p, [&](double t) { seen << t; });
    p.play();
    QCOMPARE(p.time(), 2.0);  // looping over a selection starts at its beginning
    // 2 s at x20 wrap in 0.1 s; wait for at least two wraps.
    auto wraps = [&seen] {
      int n = 0;
      for (int i = 1; i < seen.size(); ++i) n += seen[i] < seen[i - 1];
      return n;
    };
    QTRY_VERIFY_WITH_TIMEOUT(wraps() >= 2, 5000);
    p.pause();
    for (double t : seen) QVERIFY2(t >= 2.0 && t <= 4.0, qPrintable(QString::number(t)));
  }

  void aHoldingPanelMakesItWait() {
    Playhead p;
    p.setSpan(0.0, 100.0, 0.001);
    auto* holder = new QObject;
    QSignalSpy held(&p, &Playhead::heldChanged);
    p.hold(holder);
    QVERIFY(p.isHeld());
    p.play();
    QTest::qWait(150);
    QCOMPARE(p.time(), 0.0);  // held: playing does not advance
    p.setTime(1.0);           // scrubbing still works
    QCOMPARE(p.time(), 1.0);
    delete holder;  // a destroyed holder no longer holds
    QVERIFY(!p.isHeld());
    QCOMPARE(held.count(), 2);
    QTRY_VERIFY_WITH_TIMEOUT(p.time() > 1.0, 5000);
    // No jump over the time it waited: it goes on from 1 s, not from 1 s + the wait.
    QVERIFY2(p.time() < 1.0 + 0.1 + 0.2, qPrintable(QString::number(p.time())));
    p.pause();
  }

  void initWindow() {
    window_ = new MainWindow;
    window_->resize(1366, 768);
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    QVERIFY(!window_->playhead()->hasSpan());
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(kSampleLog);
    QVERIFY(opened.wait(30000));
    Playhead* p = window_->playhead();
    const IdData* d = window_->workspace()->raw();
    QVERIFY(p->hasSpan());
    QCOMPARE(p->start(), d->startTime);
    QCOMPARE(p->end(), d->timeAt(d->samples() - 1));
    QCOMPARE(p->sampleTime(), d->sampleTime);
    // Compare needs a validation range and a model to draw anything over time.
    window_->workspace()->setRange(RangeKind::Validation, {12.0, 17.0});
    ModelEntry e;
    e.name = "three-mass";
    e.model = std::shared_ptr<const PhysicalModel>(makeModel("three-mass"));
    window_->workspace()->addModel(e);
    QTRY_VERIFY_WITH_TIMEOUT(!window_->isBusy(), 60000);  // Compare simulates in the background
  }

  void oneTimeMovesEveryPanel() {
    Playhead* p = window_->playhead();
    ArmScene* scene = window_->armPanel()->scene();
    p->setTime(12.0);
    const double axisBefore = scene->drawnAngle(ArmPart::Arm);
    p->setTime(14.5);
    QCOMPARE(window_->logPanel()->playheadCursor()->shownTime(), 14.5);
    QVERIFY(window_->logPanel()->playheadCursor()->isInView());
    QCOMPARE(window_->comparePanel()->playheadCursor()->shownTime(), 14.5);
    QVERIFY(window_->comparePanel()->playheadCursor()->isInView());
    // Every time plot of the window (Log, Compare, the Model panel's simulation, Discovery's
    // residuals and overlay) holds its cursor at the playhead.
    const auto cursors = window_->findChildren<PlayheadCursor*>();
    QVERIFY2(cursors.size() >= 5, qPrintable(QString::number(cursors.size())));
    for (const PlayheadCursor* c : cursors) {
      QCOMPARE(c->playhead(), p);
      QCOMPARE(c->shownTime(), 14.5);
    }
    QVERIFY2(window_->armPanel()->statusText().startsWith("t = 14.500 s"),
             qPrintable(window_->armPanel()->statusText()));
    QVERIFY(scene->drawnAngle(ArmPart::Arm) != axisBefore);
    // The arm shows the log's motor angle at that time, through the gear.
    const IdData* d = window_->workspace()->raw();
    const std::size_t i = static_cast<std::size_t>(std::llround((14.5 - d->startTime) / d->sampleTime));
    const double motor = d->channel(columns::kMotorAngle)->values[i];
    const std::string r = d->meta("gear_ratio");
    const double gear = r.empty() ? 1.0 / 118.0 : std::stod(r);
    QCOMPARE(scene->pose().motor, motor);
    const double drawn = window_->armPanel()->magnification() * gear * motor;
    QVERIFY(std::abs(scene->drawnAngle(ArmPart::Arm) - drawn) < 1e-12);
    QCOMPARE(window_->transportBar()->slider()->value(),
             static_cast<int>(std::lround((14.5 - p->start()) / (p->end() - p->start()) * 100000)));
  }

  void aClickInATimePlotMovesIt() {
    Playhead* p = window_->playhead();
    LogPanel* log = window_->logPanel();
    log->showAll();
    const int y = static_cast<int>(log->channelRect(1)->center().y());
    const QPoint at(static_cast<int>(std::lround(log->pixelForTime(8.0))), y);
    click(log->plot(), at);
    const double pixel = p->end() / log->channelRect(0)->width();
    QVERIFY2(std::abs(p->time() - 8.0) <= 1.5 * pixel, qPrintable(QString::number(p->time())));
    // A drag pans and leaves the playhead where it was.
    const double was = p->time();
    QTest::mousePress(log->plot(), Qt::LeftButton, Qt::NoModifier, at);
    QTest::mouseMove(log->plot(), at + QPoint(60, 0));
    QTest::mouseRelease(log->plot(), Qt::LeftButton, Qt::NoModifier, at + QPoint(60, 0));
    QCOMPARE(p->time(), was);
    log->showAll();
    // The Compare plot (validation range, 12-17 s).
    QCustomPlot* compare = window_->comparePanel()->plot();
    compare->replot();
    const QPoint c(static_cast<int>(compare->xAxis->coordToPixel(15.0)),
                   static_cast<int>(compare->axisRect()->center().y()));
    click(compare, c);
    QVERIFY2(std::abs(p->time() - 15.0) < 0.05, qPrintable(QString::number(p->time())));
  }

  void transportAndKeysMoveIt() {
    Playhead* p = window_->playhead();
    TransportBar* bar = window_->transportBar();
    bar->slider()->setValue(50000);  // the middle of the log
    QVERIFY(std::abs(p->time() - 0.5 * (p->start() + p->end())) < 1e-9);
    const double t = p->time();
    key(Qt::Key_Right, Qt::ControlModifier);  // one sample
    QVERIFY(std::abs(p->time() - t - p->sampleTime()) < 1e-12);
    key(Qt::Key_Left, Qt::ShiftModifier);  // one second back
    QVERIFY(std::abs(p->time() - (t + p->sampleTime() - 1.0)) < 1e-9);
    key(Qt::Key_Up);
    QCOMPARE(p->speed(), 2.0);
    key(Qt::Key_Down);
    QCOMPARE(p->speed(), 1.0);
    key(Qt::Key_Home);
    QCOMPARE(p->time(), p->start());
    key(Qt::Key_Space);
    QVERIFY(p->isPlaying());
    QTRY_VERIFY_WITH_TIMEOUT(p->time() > p->start(), 5000);
    QTRY_VERIFY_WITH_TIMEOUT(window_->logPanel()->playheadCursor()->shownTime() > p->start(), 5000);
    QTest::qWait(300);
    test::saveShot(window_->grab().toImage(), "playhead_window");
    key(Qt::Key_Space);
    QVERIFY(!p->isPlaying());
    QTest::mouseClick(bar->playButton(), Qt::LeftButton);
    QVERIFY(p->isPlaying());
    QTest::mouseClick(bar->playButton(), Qt::LeftButton);
    QVERIFY(!p->isPlaying());
  }

  void loopSelectionIsDraggedInTheLogPanel() {
    Playhead* p = window_->playhead();
    LogPanel* log = window_->logPanel();
    log->setMode(LogPanel::Mode::SelectLoop);
    const int y = static_cast<int>(log->channelRect(0)->center().y());
    const QPoint a(static_cast<int>(std::lround(log->pixelForTime(3.0))), y);
    const QPoint b(static_cast<int>(std::lround(log->pixelForTime(6.0))), y);
    QTest::mousePress(log->plot(), Qt::LeftButton, Qt::NoModifier, a);
    for (int i = 1; i <= 8; ++i) test::moveMouse(log->plot(), a + (b - a) * i / 8, Qt::LeftButton);
    QTest::mouseRelease(log->plot(), Qt::LeftButton, Qt::NoModifier, b);
    log->setMode(LogPanel::Mode::Navigate);
    QVERIFY(p->selection().has_value());
    QVERIFY(std::abs(p->selection()->first - 3.0) < 0.1);
    QVERIFY(std::abs(p->selection()->second - 6.0) < 0.1);
    // The estimation range was not touched by the loop selection.
    QVERIFY(!window_->workspace()->range(RangeKind::Estimation).has_value());
  }

  void cleanupTestCase() { delete window_; }
};

int main(int argc, char** argv) {
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName("FlexArmPlayheadTests");
  PlayheadTest t;
  return QTest::qExec(&t, argc, argv);
}

#include "tst_playhead.moc"
