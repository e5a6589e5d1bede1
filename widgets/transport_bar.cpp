#include "widgets/transport_bar.h"

#include <QComboBox>
#include <QDoubleSpinBox>
#include <QHBoxLayout>
#include <QKeyEvent>
#include <QLabel>
#include <QSignalBlocker>
#include <QSlider>
#include <QStyle>
#include <QToolButton>
#include <algorithm>
#include <cmath>
#include <vector>

#include "widgets/playhead.h"

namespace flexarm {
namespace {
constexpr int kSliderSteps = 100000;  // 6 ms of a 10-minute log per step

QString speedText(double s) {
  return QString::fromUtf8("\u00d7") + QString::number(s, 'g', 3);
}

// Index of the offered speed nearest to s (on a log scale).
int nearestSpeed(double s) {
  const auto& list = TransportBar::speeds();
  int best = 0;
  for (int i = 1; i < static_cast<int>(list.size()); ++i)
    if (std::abs(std::log(list[static_cast<std::size_t>(i)] / s)) <
        std::abs(std::log(list[static_cast<std::size_t>(best)] / s)))
      best = i;
  return best;
}
}  // namespace

const std::vector<double>& TransportBar::speeds() {
  static const std::vector<double> list = {0.1, 0.2, 0.5, 1, 2, 5, 10, 20, 50, 100};
  return list;
}

TransportBar::TransportBar(Playhead* playhead, QWidget* parent)
    : QWidget(parent), playhead_(playhead), play_(new QToolButton(this)),
      back_(new QToolButton(this)), forward_(new QToolButton(this)),
      slider_(new QSlider(Qt::Horizontal, this)), time_(new QDoubleSpinBox(this)),
      total_(new QLabel(this)), speed_(new QComboBox(this)), loop_(new QToolButton(this)),
      selection_(new QLabel(this)), clearSelection_(new QToolButton(this)) {
  setObjectName("transportBar");
  // The buttons take no keyboard focus, so Space and the arrows stay the playhead's.
  for (QToolButton* b : {play_, back_, forward_, loop_, clearSelection_}) b->setFocusPolicy(Qt::NoFocus);
  play_->setObjectName("playButton");
  play_->setIcon(style()->standardIcon(QStyle::SP_MediaPlay));
  play_->setToolTip(tr("Play / pause (Space)"));
  back_->setObjectName("stepBackButton");
  back_->setIcon(style()->standardIcon(QStyle::SP_MediaSeekBackward));
  back_->setToolTip(tr("Step back one frame (Left; Shift: 1 s, Ctrl: one sample)"));
  back_->setAutoRepeat(true);
  forward_->setObjectName("stepForwardButton");
  forward_->setIcon(style()->standardIcon(QStyle::SP_MediaSeekForward));
  forward_->setToolTip(tr("Step forward one frame (Right; Shift: 1 s, Ctrl: one sample)"));
  forward_->setAutoRepeat(true);
  slider_->setObjectName("scrubSlider");
  slider_->setRange(0, kSliderSteps);
  slider_->setFocusPolicy(Qt::NoFocus);
  slider_->setToolTip(tr("Drag to scrub through the log"));
  time_->setObjectName("timeEdit");
  time_->setDecimals(4);
  time_->setSuffix(" s");
  time_->setKeyboardTracking(false);
  time_->setToolTip(tr("Time of the playhead; type a time to go there"));
  total_->setObjectName("totalLabel");
  speed_->setObjectName("speedCombo");
  speed_->setFocusPolicy(Qt::NoFocus);
  for (double s : speeds()) speed_->addItem(speedText(s), s);
  speed_->setCurrentIndex(nearestSpeed(playhead_->speed()));
  speed_->setToolTip(tr("Playback speed against real time (Up / Down)"));
  loop_->setObjectName("loopButton");
  loop_->setText(tr("Loop"));
  loop_->setCheckable(true);
  loop_->setToolTip(tr("Loop over the selection (drag it in the Log panel's loop mode, L), "
                       "or over the whole log"));
  selection_->setObjectName("selectionLabel");
  clearSelection_->setText(QString::fromUtf8("\u00d7"));
  clearSelection_->setToolTip(tr("Clear the loop selection"));

  auto* layout = new QHBoxLayout(this);
  layout->setContentsMargins(4, 0, 4, 0);
  layout->addWidget(back_);
  layout->addWidget(play_);
  layout->addWidget(forward_);
  layout->addWidget(slider_, 1);
  layout->addWidget(time_);
  layout->addWidget(total_);
  auto* speedLabel = new QLabel(tr("Speed"), this);
  speedLabel->setObjectName("speedLabel");
  speedLabel->setToolTip(speed_->toolTip());
  speedLabel->setBuddy(speed_);
  layout->addWidget(speedLabel);
  layout->addWidget(speed_);
  layout->addWidget(loop_);
  layout->addWidget(selection_);
  layout->addWidget(clearSelection_);

  connect(play_, &QToolButton::clicked, playhead_, &Playhead::togglePlaying);
  connect(back_, &QToolButton::clicked, playhead_, [this] { playhead_->stepFrames(-1); });
  connect(forward_, &QToolButton::clicked, playhead_, [this] { playhead_->stepFrames(1); });
  connect(slider_, &QSlider::valueChanged, this, [this](int v) {
    if (updating_ || !playhead_->hasSpan()) return;
    playhead_->setTime(playhead_->start() +
                       (playhead_->end() - playhead_->start()) * v / kSliderSteps);
  });
  connect(time_, QOverload<double>::of(&QDoubleSpinBox::valueChanged), this, [this](double t) {
    if (!updating_) playhead_->setTime(t);
  });
  connect(speed_, QOverload<int>::of(&QComboBox::currentIndexChanged), this,
          [this](int i) { playhead_->setSpeed(speed_->itemData(i).toDouble()); });
  connect(loop_, &QToolButton::toggled, playhead_, &Playhead::setLooping);
  connect(clearSelection_, &QToolButton::clicked, playhead_, &Playhead::clearSelection);

  connect(playhead_, &Playhead::timeChanged, this, &TransportBar::onTime);
  connect(playhead_, &Playhead::spanChanged, this, &TransportBar::onSpan);
  connect(playhead_, &Playhead::selectionChanged, this, &TransportBar::onSelection);
  connect(playhead_, &Playhead::playingChanged, this, [this](bool on) {
    play_->setIcon(style()->standardIcon(on ? QStyle::SP_MediaPause : QStyle::SP_MediaPlay));
  });
  connect(playhead_, &Playhead::speedChanged, this, [this](double s) {
    const QSignalBlocker block(speed_);
    speed_->setCurrentIndex(nearestSpeed(s));
  });
  connect(playhead_, &Playhead::loopingChanged, this, [this](bool on) {
    const QSignalBlocker block(loop_);
    loop_->setChecked(on);
  });
  onSpan();
}

QString TransportBar::timeText() const {
  return QString("%1 / %2").arg(time_->text(), total_->text());
}

void TransportBar::onTime(double t) {
  updating_ = true;
  const double span = playhead_->end() - playhead_->start();
  slider_->setValue(span > 0 ? static_cast<int>(std::lround((t - playhead_->start()) / span *
                                                            kSliderSteps))
                             : 0);
  time_->setValue(t);
  updating_ = false;
}

void TransportBar::onSpan() {
  const bool has = playhead_->hasSpan();
  for (QWidget* w : std::initializer_list<QWidget*>{play_, back_, forward_, slider_, time_, loop_})
    w->setEnabled(has);
  updating_ = true;
  time_->setRange(has ? playhead_->start() : 0.0, has ? playhead_->end() : 0.0);
  time_->setSingleStep(has ? playhead_->sampleTime() : 0.001);
  updating_ = false;
  total_->setText(has ? tr("of %1 s").arg(playhead_->end(), 0, 'f', 3) : tr("no log"));
  onTime(playhead_->time());
  onSelection();
}

void TransportBar::onSelection() {
  const auto s = playhead_->selection();
  selection_->setText(s ? tr("%1-%2 s").arg(s->first, 0, 'f', 3).arg(s->second, 0, 'f', 3)
                        : QString());
  clearSelection_->setVisible(s.has_value());
}

bool TransportBar::handleKey(Playhead* playhead, QKeyEvent* e) {
  if (!playhead || !playhead->hasSpan()) return false;
  const auto mods = e->modifiers() & (Qt::ShiftModifier | Qt::ControlModifier | Qt::AltModifier);
  auto step = [&](int sign) {
    if (mods == Qt::ShiftModifier) playhead->stepSeconds(sign * 1.0);
    else if (mods == Qt::ControlModifier) playhead->stepSamples(sign);
    else playhead->stepFrames(sign);
  };
  auto speedStep = [&](int d) {
    const auto& list = speeds();
    const int i = std::clamp(nearestSpeed(playhead->speed()) + d, 0,
                             static_cast<int>(list.size()) - 1);
    playhead->setSpeed(list[static_cast<std::size_t>(i)]);
  };
  switch (e->key()) {
    case Qt::Key_Space:
      if (mods) return false;
      playhead->togglePlaying();
      return true;
    case Qt::Key_Left: step(-1); return true;
    case Qt::Key_Right: step(1); return true;
    case Qt::Key_Home: playhead->setTime(playhead->start()); return true;
    case Qt::Key_End: playhead->setTime(playhead->end()); return true;
    case Qt::Key_Up: speedStep(1); return true;
    case Qt::Key_Down: speedStep(-1); return true;
    default: return false;
  }
}

}  // namespace flexarm
