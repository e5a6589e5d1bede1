// Playback of a 10-minute 2 kHz log in the window at 1366x768 (the Log panel and the Arm dock
// with the three-mass model's masses): frames per second the Arm view renders while playing at
// x1 and x100, the cost of a frame of the whole window (every panel following the playhead,
// driven as fast as it goes), that a paused window renders nothing, and how long the masses'
// simulation of the log takes off the GUI thread. Needs a display (xvfb-run).
// Usage: bench_playback [seconds of playing per speed, default 10]
#include <QApplication>
#include <QDockWidget>
#include <QElapsedTimer>
#include <QSignalSpy>
#include <QThread>
#include <QTimer>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <algorithm>
#include <functional>

#include "app/main_window.h"
#include "core/sim/closed_loop.h"
#include "widgets/arm/vtk_view.h"
#include "widgets/arm_panel.h"
#include "widgets/playhead.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {

// CPU seconds of the whole process (the GUI thread and Mesa's rendering threads): what a frame
// costs regardless of what else the machine is running, unlike wall-clock time.
double processCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

void waitMs(int ms) {
  QElapsedTimer t;
  t.start();
  while (t.elapsed() < ms) QApplication::processEvents(QEventLoop::AllEvents, 5);
}

struct Played {
  double fps = 0.0, renderMs = 0.0, worstMs = 0.0, ticksPerSecond = 0.0, logSeconds = 0.0;
  double cpuPerFrameMs = 0.0;
};

Played play(MainWindow& w, double speed, int seconds) {
  Playhead* p = w.playhead();
  VtkView* view = w.armPanel()->view();
  p->setTime(60.0);
  p->setSpeed(speed);
  waitMs(200);
  view->resetFrameStats();
  QElapsedTimer wall;
  wall.start();
  const double t0 = p->time();
  const double cpu0 = processCpuSeconds();
  p->play();
  waitMs(1000 * seconds);
  p->pause();
  const double s = wall.nsecsElapsed() * 1e-9;
  const double cpu = processCpuSeconds() - cpu0;
  const auto stats = view->frameStats();
  Played r;
  r.fps = stats.frames / s;
  r.renderMs = stats.frames ? 1e3 * stats.renderSeconds / stats.frames : 0.0;
  r.worstMs = 1e3 * stats.worstSeconds;
  r.ticksPerSecond = p->measuredFps();
  r.logSeconds = p->time() - t0;
  r.cpuPerFrameMs = stats.frames ? 1e3 * cpu / stats.frames : 0.0;
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  const int seconds = argc > 1 ? std::max(2, std::atoi(argv[1])) : 10;
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName("FlexArmBench");

  std::printf("Making a 10-minute 2 kHz log of the three-mass arm (closed loop, chirp)...\n");
  auto model = makeModel("three-mass");
  SimulationOptions o;
  o.durationS = 600.0;
  o.logRateHz = 2000.0;
  o.excitation.chirpStartHz = 30.0;
  o.excitation.chirpEndHz = 0.5;
  o.logMotorVelocity = true;
  const auto a = std::chrono::steady_clock::now();
  SimulationResult sim = simulateClosedLoop(*model, {}, o);
  std::printf("  %zu samples, %zu channels, simulated in %.1f s\n", sim.data.samples(),
              sim.data.channels.size(),
              std::chrono::duration<double>(std::chrono::steady_clock::now() - a).count());

  MainWindow w;
  for (auto* dock : w.findChildren<QDockWidget*>())
    if (dock->objectName() != "armDock") dock->hide();
  w.resize(1366, 768);
  w.show();
  waitMs(500);
  w.workspace()->setLog(std::move(sim.data), "bench_10min_2khz.csv");
  ModelEntry e;
  e.name = "three-mass";
  e.model = std::shared_ptr<const PhysicalModel>(makeModel("three-mass"));
  const int index = w.workspace()->addModel(e);
  waitMs(3000);  // the panels draw the new log first: not part of choosing the model
  QSignalSpy ready(w.armPanel(), &ArmPanel::anglesReady);
  QElapsedTimer masses;
  masses.start();
  w.armPanel()->selectModel(index);
  // The window stays live while the masses are simulated: the event loop turns every few
  // milliseconds; the longest turn is the longest the window did not answer.
  int uiTurns = 0;
  double longestTurnMs = 0.0;
  while (ready.isEmpty()) {
    QElapsedTimer turn;
    turn.start();
    QApplication::processEvents(QEventLoop::AllEvents, 5);
    QThread::msleep(1);
    longestTurnMs = std::max(longestTurnMs, turn.nsecsElapsed() * 1e-6);
    ++uiTurns;
  }
  const auto angles = w.armPanel()->bodyAngles();
  if (!angles) {
    std::printf("the masses could not be simulated: %s\n", qPrintable(ready.first().at(1).toString()));
    return 1;
  }
  std::printf("Masses simulated off the GUI thread in %.2f s (worker %.2f s; %d event-loop turns "
              "meanwhile, the longest %.0f ms); window %dx%d, arm view %dx%d\n",
              masses.nsecsElapsed() * 1e-9, angles->seconds, uiTurns, longestTurnMs, w.width(), w.height(),
              w.armPanel()->view()->width(), w.armPanel()->view()->height());

  for (double speed : {1.0, 100.0}) {
    const Played r = play(w, speed, seconds);
    std::printf("Playing at x%g for %d s: arm view %.1f frames/s (render %.2f ms mean, %.1f ms "
                "worst; %.1f ms of CPU a frame), playhead %.1f ticks/s, %.2f s of log played\n",
                speed, seconds, r.fps, r.renderMs, r.worstMs, r.cpuPerFrameMs, r.ticksPerSecond,
                r.logSeconds);
  }

  // The cost of one frame, driven as fast as it goes: the whole window (every panel follows
  // the playhead), the Arm view alone, and the other panels without the Arm view.
  Playhead* p = w.playhead();
  VtkView* view = w.armPanel()->view();
  auto driven = [&](const char* what, const std::function<void(double)>& step) {
    step(120.0);
    waitMs(200);
    view->resetFrameStats();
    const int frames = 300;
    QElapsedTimer all;
    all.start();
    const double cpu0 = processCpuSeconds();
    for (int i = 1; i <= frames; ++i) {
      step(120.0 + i / 60.0);
      QApplication::processEvents();
    }
    const double s = all.nsecsElapsed() * 1e-9;
    const double cpu = processCpuSeconds() - cpu0;
    std::printf("Driven as fast as it goes, %s: %.1f ms a frame (%.0f frames/s), %.1f ms of CPU "
                "a frame; %lld arm renders\n",
                what, 1e3 * s / frames, frames / s, 1e3 * cpu / frames,
                static_cast<long long>(view->frameStats().frames));
  };
  driven("whole window", [&](double t) { p->setTime(t); });
  driven("Arm view alone", [&](double t) { w.armPanel()->showTime(t); });
  w.armPanel()->setPlayhead(nullptr);
  driven("every panel but the Arm view", [&](double t) { p->setTime(t); });
  w.armPanel()->setPlayhead(p);  // redraws once

  waitMs(300);
  view->resetFrameStats();
  waitMs(2000);
  std::printf("Paused for 2 s: %lld arm renders\n", static_cast<long long>(view->frameStats().frames));
  return 0;
}
