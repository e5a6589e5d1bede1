#include "widgets/arm_panel.h"

#include <QHBoxLayout>
#include <QLabel>
#include <QSpinBox>
#include <QVBoxLayout>
#include <cmath>

#include "widgets/arm/arm_scene.h"
#include "widgets/arm/vtk_view.h"
#include "widgets/playhead.h"

namespace flexarm {

ArmPanel::ArmPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), scene_(std::make_unique<ArmScene>()),
      view_(new VtkView(this)), magnify_(new QSpinBox(this)), label_(new QLabel(this)) {
  setObjectName("armPanel");
  view_->setObjectName("armView");
  view_->setRenderer(scene_->renderer());
  view_->setResetCamera([this] { scene_->resetCamera(); });
  magnify_->setRange(1, 100000);
  magnify_->setValue(100);
  magnify_->setPrefix(QString::fromUtf8("\u00d7"));
  magnify_->setToolTip(tr("Magnification of the arm motion (the gear turns the arm 1/118 of "
                          "the motor angle)"));
  label_->setObjectName("armLabel");
  auto* controls = new QHBoxLayout;
  controls->addWidget(label_, 1);
  controls->addWidget(magnify_);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(2, 2, 2, 2);
  layout->addWidget(view_, 1);
  layout->addLayout(controls);
  connect(magnify_, QOverload<int>::of(&QSpinBox::valueChanged), this, [this] {
    showTime(playhead_ ? playhead_->time() : 0.0);
  });
  connect(workspace_, &Workspace::currentChanged, this, &ArmPanel::onDataChanged);
  onDataChanged();
}

ArmPanel::~ArmPanel() = default;

void ArmPanel::setPlayhead(Playhead* playhead) {
  if (playhead_) disconnect(playhead_, nullptr, this, nullptr);
  playhead_ = playhead;
  if (playhead_) connect(playhead_, &Playhead::timeChanged, this, &ArmPanel::showTime);
  onDataChanged();
}

QString ArmPanel::labelText() const { return label_->text(); }

void ArmPanel::onDataChanged() {
  const IdData* d = workspace_->raw();
  const bool usable = d && d->channel(columns::kMotorAngle);
  if (!usable) {
    label_->setText(d ? tr("The data have no motor_angle_rad channel to move the arm")
                      : tr("Drag to rotate, wheel to zoom, double click to reset"));
    scene_->setPose(0, 0);
    view_->update();
    return;
  }
  const std::string r = d->meta("gear_ratio");
  gearRatio_ = r.empty() ? 1.0 / 118.0 : std::atof(r.c_str());
  if (!(gearRatio_ > 0 && std::isfinite(gearRatio_))) gearRatio_ = 1.0 / 118.0;
  showTime(playhead_ ? playhead_->time() : d->startTime);
}

void ArmPanel::showTime(double t) {
  const IdData* d = workspace_->raw();
  const Channel* angle = d ? d->channel(columns::kMotorAngle) : nullptr;
  if (!angle || angle->values.empty()) return;
  const double pos = std::round((t - d->startTime) / d->sampleTime);
  const auto i = static_cast<std::size_t>(
      std::clamp(pos, 0.0, static_cast<double>(angle->values.size() - 1)));
  const double motor = angle->values[i];
  const double axis = gearRatio_ * motor * magnify_->value();
  scene_->setPose(axis, 0.0);
  label_->setText(tr("t = %1 s   motor %2 rad   axis one %3 mrad")
                      .arg(d->timeAt(i), 0, 'f', 3)
                      .arg(motor, 0, 'g', 4)
                      .arg(1000.0 * gearRatio_ * motor, 0, 'g', 4));
  view_->update();
}

}  // namespace flexarm
