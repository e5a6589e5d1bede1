#pragma once
// The window's one playhead: the current time of the log, shared by every panel that shows
// time (Log, Compare, Arm, Recursive, Diagnosis). It plays at a speed of x0.1 ... x100 of real
// time, pauses, scrubs, steps, and loops over a selection.
//
// Contract for panels (keep it stable: several panels are written against it)
// - Ownership: the main window owns the one Playhead and hands it to panels with
//   `panel->setPlayhead(playhead)`; a panel never creates its own. The main window sets the
//   span from the loaded log (setSpan); times are the log's seconds (IdData::timeAt), the same
//   in raw and preprocessed data.
// - Following: connect to timeChanged(t) and show t (a cursor line, a pose, a row). The slot
//   runs on the GUI thread up to 60 times a second while playing, so it must be cheap: move an
//   item and ask for a repaint, never recompute in it. time() always holds the current value.
// - Moving: call setTime(t) when the user points at a time (a click in a time plot, a row);
//   it clamps t into the span and emits timeChanged only when the time moved. Playing,
//   stepping and looping are the playhead's own job (play/pause/step*/setLooping).
// - A panel that computes as it plays (e.g. a recursive estimator that must reach t) and
//   cannot keep up calls hold(this) when it falls behind and release(this) once it has caught
//   up. While any panel holds, playing does not advance (and does not jump when released: it
//   goes on from where it stopped). Holding does not stop scrubbing or setTime. A hold is
//   dropped when its holder is destroyed.
// - Signals: timeChanged (every move), playingChanged, speedChanged, spanChanged (a log was
//   loaded or closed: rebuild), selectionChanged, loopingChanged, heldChanged.
#include <QElapsedTimer>
#include <QObject>
#include <optional>
#include <map>
#include <utility>

class QTimer;

namespace flexarm {

class Playhead : public QObject {
  Q_OBJECT
 public:
  static constexpr double kMinSpeed = 0.1;
  static constexpr double kMaxSpeed = 100.0;

  explicit Playhead(QObject* parent = nullptr);

  // The times the playhead can take, [start, end], and the sample time of a one-sample step.
  // Puts the time at start, pauses, and clears the selection when the span changes.
  void setSpan(double start, double end, double sampleTime);
  void clearSpan();
  bool hasSpan() const { return end_ >= start_; }
  double start() const { return start_; }
  double end() const { return end_; }
  double sampleTime() const { return sampleTime_; }

  double time() const { return time_; }
  // Moves to t, clamped into the span; emits timeChanged if the time moved.
  void setTime(double t);
  // Steps by n frames of playing at the current speed (at least one sample each), or by n
  // samples, or by seconds; negative goes back.
  void stepFrames(int n);
  void stepSamples(int n);
  void stepSeconds(double seconds);

  bool isPlaying() const { return playing_; }
  void play();
  void pause();
  void togglePlaying();
  // Playback speed as a multiple of real time, clamped to [kMinSpeed, kMaxSpeed].
  double speed() const { return speed_; }
  void setSpeed(double speed);

  // Selection [t0, t1] to loop over (seconds, clipped to the span).
  void setSelection(double t0, double t1);
  void clearSelection();
  std::optional<std::pair<double, double>> selection() const { return selection_; }
  // Looping plays the selection (or the whole span without one) again and again; without
  // looping, playing stops at the end.
  void setLooping(bool on);
  bool isLooping() const { return looping_; }

  // A panel that computes as it plays asks the playhead to wait for it (see the contract).
  void hold(const QObject* holder);
  void release(const QObject* holder);
  bool isHeld() const { return !holders_.empty(); }

  // Frames (timer ticks) per second of wall-clock time while playing, over the last second.
  double measuredFps() const { return fps_; }
  // Playing advances the time every frameIntervalMs (60 frames a second by default).
  int frameIntervalMs() const;
  // Log seconds one frame of playing advances at the current speed.
  double frameSeconds() const;

 signals:
  void timeChanged(double t);
  void playingChanged(bool playing);
  void speedChanged(double speed);
  void spanChanged();
  void selectionChanged();
  void loopingChanged(bool looping);
  void heldChanged(bool held);

 private:
  void tick();
  // Where playing starts and wraps: the selection when looping over one, else the span.
  std::pair<double, double> playRange() const;

  QTimer* timer_;
  QElapsedTimer clock_;
  qint64 lastTickNs_ = 0;
  double start_ = 0.0, end_ = -1.0, sampleTime_ = 1.0;
  double time_ = 0.0;
  double speed_ = 1.0;
  bool playing_ = false;
  bool looping_ = false;
  std::optional<std::pair<double, double>> selection_;
  std::map<const QObject*, QMetaObject::Connection> holders_;  // to its destroyed()
  // Frame rate measurement: frames in the current one-second window.
  qint64 fpsWindowStartNs_ = 0;
  int fpsFrames_ = 0;
  double fps_ = 0.0;
};

}  // namespace flexarm
