#include "widgets/playhead.h"

#include <QTimer>
#include <algorithm>
#include <cmath>

namespace flexarm {
namespace {
constexpr int kFrameIntervalMs = 16;  // about 60 frames a second
// After a stall (a held playhead, a busy machine) playing goes on from where it was instead
// of jumping over the time the window could not show.
constexpr double kMaxFrameWallSeconds = 0.1;
}  // namespace

Playhead::Playhead(QObject* parent) : QObject(parent), timer_(new QTimer(this)) {
  setObjectName("playhead");
  timer_->setTimerType(Qt::PreciseTimer);
  timer_->setInterval(kFrameIntervalMs);
  connect(timer_, &QTimer::timeout, this, &Playhead::tick);
  clock_.start();
}

int Playhead::frameIntervalMs() const { return kFrameIntervalMs; }

double Playhead::frameSeconds() const { return speed_ * kFrameIntervalMs / 1000.0; }

void Playhead::setSpan(double start, double end, double sampleTime) {
  pause();
  start_ = start;
  end_ = std::max(start, end);
  sampleTime_ = sampleTime > 0 && std::isfinite(sampleTime) ? sampleTime : 1.0;
  selection_.reset();
  time_ = start_;
  emit spanChanged();
  emit selectionChanged();
  emit timeChanged(time_);
}

void Playhead::clearSpan() {
  pause();
  start_ = 0.0;
  end_ = -1.0;
  selection_.reset();
  time_ = 0.0;
  emit spanChanged();
  emit selectionChanged();
  emit timeChanged(time_);
}

void Playhead::setTime(double t) {
  if (!hasSpan() || !std::isfinite(t)) return;
  t = std::clamp(t, start_, end_);
  if (t == time_) return;
  time_ = t;
  emit timeChanged(time_);
}

void Playhead::stepFrames(int n) {
  stepSeconds(n * std::max(frameSeconds(), sampleTime_));
}

void Playhead::stepSamples(int n) { stepSeconds(n * sampleTime_); }

void Playhead::stepSeconds(double seconds) { setTime(time_ + seconds); }

void Playhead::play() {
  if (playing_ || !hasSpan() || end_ <= start_) return;
  const auto [a, b] = playRange();
  // Play from the start of what plays when at its end or outside a looped selection.
  if (time_ >= b || (looping_ && selection_ && time_ < a)) setTime(a);
  playing_ = true;
  lastTickNs_ = clock_.nsecsElapsed();
  fpsWindowStartNs_ = lastTickNs_;
  fpsFrames_ = 0;
  timer_->start();
  emit playingChanged(true);
}

void Playhead::pause() {
  if (!playing_) return;
  playing_ = false;
  timer_->stop();
  emit playingChanged(false);
}

void Playhead::togglePlaying() { playing_ ? pause() : play(); }

void Playhead::setSpeed(double speed) {
  if (!std::isfinite(speed)) return;
  speed = std::clamp(speed, kMinSpeed, kMaxSpeed);
  if (speed == speed_) return;
  speed_ = speed;
  emit speedChanged(speed_);
}

void Playhead::setSelection(double t0, double t1) {
  if (!hasSpan()) return;
  if (t1 < t0) std::swap(t0, t1);
  t0 = std::clamp(t0, start_, end_);
  t1 = std::clamp(t1, start_, end_);
  if (!(t1 > t0)) {
    clearSelection();
    return;
  }
  selection_ = std::make_pair(t0, t1);
  emit selectionChanged();
}

void Playhead::clearSelection() {
  if (!selection_) return;
  selection_.reset();
  emit selectionChanged();
}

void Playhead::setLooping(bool on) {
  if (on == looping_) return;
  looping_ = on;
  emit loopingChanged(on);
}

void Playhead::hold(const QObject* holder) {
  if (!holder || holders_.count(holder)) return;
  const bool was = isHeld();
  holders_[holder] =
      connect(holder, &QObject::destroyed, this, [this, holder] { release(holder); });
  if (!was) emit heldChanged(true);
}

void Playhead::release(const QObject* holder) {
  const auto it = holders_.find(holder);
  if (it == holders_.end()) return;
  disconnect(it->second);
  holders_.erase(it);
  if (!isHeld()) {
    lastTickNs_ = clock_.nsecsElapsed();  // no jump over the time spent waiting
    emit heldChanged(false);
  }
}

std::pair<double, double> Playhead::playRange() const {
  if (looping_ && selection_) return *selection_;
  return {start_, end_};
}

void Playhead::tick() {
  if (!playing_) return;
  const qint64 now = clock_.nsecsElapsed();
  const double wall = std::min(kMaxFrameWallSeconds, (now - lastTickNs_) * 1e-9);
  lastTickNs_ = now;
  ++fpsFrames_;
  if (now - fpsWindowStartNs_ >= 1000000000LL) {
    fps_ = fpsFrames_ * 1e9 / static_cast<double>(now - fpsWindowStartNs_);
    fpsWindowStartNs_ = now;
    fpsFrames_ = 0;
  }
  if (isHeld()) return;
  const auto [a, b] = playRange();
  double t = time_ + speed_ * wall;
  if (t > b) {
    if (!looping_) {
      setTime(b);
      pause();
      return;
    }
    t = b > a ? a + std::fmod(t - b, b - a) : a;
  }
  setTime(t);
}

}  // namespace flexarm
