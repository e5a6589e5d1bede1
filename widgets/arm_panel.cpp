#include "widgets/arm_panel.h"

#include <QHBoxLayout>
#include <QLabel>
#include <QSlider>
#include <QSpinBox>
#include <QTimer>
#include <QToolButton>
#include <QVBoxLayout>
#include <cmath>

#include "widgets/arm/arm_scene.h"
#include "widgets/arm/vtk_view.h"

namespace flexarm {

ArmPanel::ArmPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), scene_(std::make_unique<ArmScene>()),
      view_(new VtkView(this)), time_(new QSlider(Qt::Horizontal, this)),
      play_(new QToolButton(this)), magnify_(new QSpinBox(this)), label_(new QLabel(this)),
      timer_(new QTimer(this)) {
  setObjectName("armPanel");
  view_->setObjectName("armView");
  view_->setRenderer(scene_->renderer());
  view_->setResetCamera([this] { scene_->resetCamera(); });
  play_->setText(tr("Play"));
  play_->setCheckable(true);
  play_->setObjectName("armPlayButton");
  time_->setObjectName("armTimeSlider");
  time_->setEnabled(false);
  magnify_->setRange(1, 100000);
  magnify_->setValue(100);
  magnify_->setPrefix(QString::fromUtf8("\u00d7"));
  magnify_->setToolTip(tr("Magnification of the arm motion (the gear turns the arm 1/118 of "
                          "the motor angle)"));
  label_->setObjectName("armLabel");
  auto* controls = new QHBoxLayout;
  controls->addWidget(play_);
  controls->addWidget(time_, 1);
  controls->addWidget(magnify_);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(2, 2, 2, 2);
  layout->addWidget(view_, 1);
  layout->addLayout(controls);
  layout->addWidget(label_);
  timer_->setInterval(33);
  connect(timer_, &QTimer::timeout, this, [this] {
    const int step = std::max(1, time_->maximum() / 600);  // about 20 s for a whole log
    time_->setValue(time_->value() + step >= time_->maximum() ? 0 : time_->value() + step);
  });
  connect(play_, &QToolButton::toggled, this, [this](bool on) {
    play_->setText(on ? tr("Pause") : tr("Play"));
    on ? timer_->start() : timer_->stop();
  });
  connect(time_, &QSlider::valueChanged, this, &ArmPanel::showSample);
  connect(magnify_, QOverload<int>::of(&QSpinBox::valueChanged), this,
          [this] { showSample(time_->value()); });
  connect(workspace_, &Workspace::currentChanged, this, &ArmPanel::onDataChanged);
  onDataChanged();
}

ArmPanel::~ArmPanel() = default;

void ArmPanel::onDataChanged() {
  const IdData* d = workspace_->current();
  const bool usable = d && d->channel(columns::kMotorAngle);
  time_->setEnabled(usable);
  play_->setEnabled(usable);
  if (!usable) {
    play_->setChecked(false);
    label_->setText(d ? tr("The data have no motor_angle_rad channel to move the arm")
                      : tr("Drag to rotate, wheel to zoom, double click to reset"));
    scene_->setPose(0, 0);
    view_->update();
    return;
  }
  const std::string r = d->meta("gear_ratio");
  gearRatio_ = r.empty() ? 1.0 / 118.0 : std::atof(r.c_str());
  if (!(gearRatio_ > 0 && std::isfinite(gearRatio_))) gearRatio_ = 1.0 / 118.0;
  time_->setRange(0, static_cast<int>(d->samples()) - 1);
  time_->setValue(0);
  showSample(0);
}

void ArmPanel::showSample(int i) {
  const IdData* d = workspace_->current();
  const Channel* angle = d ? d->channel(columns::kMotorAngle) : nullptr;
  if (!angle || i < 0 || static_cast<std::size_t>(i) >= angle->values.size()) return;
  const double motor = angle->values[static_cast<std::size_t>(i)];
  const double axis = gearRatio_ * motor * magnify_->value();
  scene_->setPose(axis, 0.0);
  label_->setText(tr("t = %1 s   motor %2 rad   axis one %3 mrad")
                      .arg(d->timeAt(static_cast<std::size_t>(i)), 0, 'f', 3)
                      .arg(motor, 0, 'g', 4)
                      .arg(1000.0 * gearRatio_ * motor, 0, 'g', 4));
  view_->update();
}

}  // namespace flexarm
