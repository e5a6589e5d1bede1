#include "widgets/arm_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDialog>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QGridLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QMenu>
#include <QMessageBox>
#include <QPointer>
#include <QProgressBar>
#include <QPushButton>
#include <QSettings>
#include <QSpinBox>
#include <QToolButton>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <algorithm>
#include <cmath>

#include "core/ident/fit.h"
#include "widgets/arm/arm_scene.h"
#include "widgets/arm/frame_exporter.h"
#include "widgets/arm/vtk_view.h"
#include "widgets/file_output.h"
#include "widgets/playhead.h"

namespace flexarm {
namespace {

constexpr int kLogSource = -1, kExternalSource = -2;
constexpr int kTracePoints = 400;
constexpr double kTraceSeconds = 1.0;
// Auto scales: the log's largest motion about axis one is drawn at about this angle; the
// flexing at its median (half of the log flexes more) at about that one, unless the largest
// deflection would then be drawn beyond the last (radians).
constexpr double kMotionDrawn = 0.6, kDeflectionDrawn = 0.4, kDeflectionMost = 2.5;

// v with a fixed number of decimals, without the "-0.0000" of a tiny negative (5e-22 rad
// reads 0.0000, not 5.195e-22).
QString fixed(double v, int decimals) {
  const double scale = std::pow(10.0, decimals);
  return QString::number(std::round(v * scale) / scale + 0.0, 'f', decimals);
}

// A deflection in milliradians with four decimals.
QString mrad(double rad) { return fixed(1e3 * rad, 4); }

// The largest of 1, 2, 5 times a power of ten that is at most x, clamped to [lo, hi].
int niceDown(double x, int lo, int hi) {
  if (!(x > 0) || !std::isfinite(x)) return lo;
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  const double m = x / p;
  const double nice = (m >= 5 ? 5 : m >= 2 ? 2 : 1) * p;
  return static_cast<int>(std::clamp(nice, static_cast<double>(lo), static_cast<double>(hi)));
}

// How far the tip lags behind the rigid arm (the springs' deflections added up) at the median
// of the log's samples: what the flexing looks like most of the time, where the largest
// deflection is a moment's.
double medianDeflection(const BodyAngles& a) {
  std::vector<double> total(a.samples(), 0.0);
  for (const auto* d : {&a.gearDeflection, &a.armDeflection})
    for (std::size_t k = 0; k < d->size() && k < total.size(); ++k) total[k] += std::abs((*d)[k]);
  if (total.empty()) return 0.0;
  const auto middle = total.begin() + static_cast<std::ptrdiff_t>(total.size() / 2);
  std::nth_element(total.begin(), middle, total.end());
  return *middle;
}

// The one of 1, 2, 5 times a power of ten nearest to x (on a log scale), clamped to [lo, hi].
int niceNearest(double x, int lo, int hi) {
  if (!(x > 0) || !std::isfinite(x)) return lo;
  const double p = std::pow(10.0, std::floor(std::log10(x)));
  double best = p;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (std::abs(std::log(m * p / x)) < std::abs(std::log(best / x))) best = m * p;
  return static_cast<int>(std::clamp(best, static_cast<double>(lo), static_cast<double>(hi)));
}

double gearRatioOf(const IdData& d) {
  // The log's gear ratio as the fit reads it ("1/256.86" too); else the models' default.
  return logGearRatio(d).value_or(1.0 / 118.0);
}

}  // namespace

ArmPanel::ArmPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), scene_(std::make_unique<ArmScene>()),
      view_(new VtkView(this)), source_(new QComboBox(this)),
      measured_(new QCheckBox(tr("measured motor angle"), this)), magnify_(new QSpinBox(this)),
      exaggerate_(new QSpinBox(this)), ghost_(new QCheckBox(tr("Rigid ghost"), this)),
      trace_(new QCheckBox(tr("Tip trace"), this)), export_(new QToolButton(this)),
      progress_(new QProgressBar(this)), cancel_(new QToolButton(this)),
      label_(new QLabel(this)) {
  setObjectName("armPanel");
  view_->setObjectName("armView");
  view_->setRenderer(scene_->renderer());
  view_->setResetCamera([this] { scene_->resetCamera(); });
  overlay_.colour = [this](double deflection) {
    double rgb[3];
    scene_->deflectionColor(deflection, rgb);
    return QColor::fromRgbF(static_cast<float>(rgb[0]), static_cast<float>(rgb[1]),
                            static_cast<float>(rgb[2]));
  };
  view_->setOverlay([this](QPainter& p, const QRect& area) { paintArmOverlay(p, area, overlay_); });
  source_->setObjectName("armSourceCombo");
  source_->setToolTip(tr("Where the angles come from: the log's motor angle through the gear "
                         "(rigid), or a model of the list simulated on the log's torque"));
  source_->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
  source_->setMinimumContentsLength(14);
  measured_->setObjectName("armMeasuredAngle");
  measured_->setChecked(true);
  measured_->setToolTip(tr("Turn the bodies about the log's measured motor angle and add the "
                           "simulated deflections (an open-loop simulation of a closed-loop "
                           "log drifts in angle, not in deflection); off: all simulated"));
  magnify_->setObjectName("armMagnify");
  magnify_->setRange(1, 100000);
  magnify_->setPrefix(tr("motion ") + QString::fromUtf8("\u00d7"));
  magnify_->setToolTip(tr("Magnification of the motion about axis one (the gear turns the arm "
                          "1/118 of the motor angle)"));
  exaggerate_->setObjectName("armExaggeration");
  exaggerate_->setRange(0, 1000000);
  exaggerate_->setPrefix(tr("deflection ") + QString::fromUtf8("\u00d7"));
  exaggerate_->setToolTip(tr("Exaggeration of the spring deflections (fractions of a "
                             "milliradian): a body is drawn this many times its deflection "
                             "behind the one before it"));
  ghost_->setObjectName("armGhost");
  ghost_->setChecked(true);
  ghost_->setToolTip(tr("Draw the rigid arm (no spring deflection) as a ghost to compare"));
  trace_->setObjectName("armTrace");
  trace_->setChecked(true);
  trace_->setToolTip(tr("Where the tool tip was over the last second (time runs downwards), "
                        "beside the rigid ghost's tip"));
  export_->setObjectName("armExport");
  export_->setText(tr("Export"));
  export_->setPopupMode(QToolButton::InstantPopup);
  export_->setToolTip(tr("Save the view as a still image or export frames of the motion"));
  auto* menu = new QMenu(export_);
  menu->addAction(tr("Save still..."), this, &ArmPanel::saveStill);
  menu->addAction(tr("Export frames (PNG + ffmpeg)..."), this, &ArmPanel::askExportFrames);
  export_->setMenu(menu);
  progress_->setObjectName("armProgress");
  progress_->setRange(0, 1000);
  progress_->setMaximumHeight(14);
  progress_->setVisible(false);
  cancel_->setText(tr("Cancel"));
  cancel_->setToolTip(tr("Stop exporting frames"));
  cancel_->setVisible(false);
  label_->setObjectName("armLabel");
  label_->setWordWrap(true);

  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Angles"), this));
  top->addWidget(source_, 1);
  top->addWidget(measured_);
  // Two short rows of controls: the dock stays narrow enough to sit beside the Log panel.
  auto* controls = new QGridLayout;
  controls->setContentsMargins(0, 0, 0, 0);
  controls->addWidget(magnify_, 0, 0);
  controls->addWidget(exaggerate_, 0, 1);
  controls->addWidget(ghost_, 1, 0);
  controls->addWidget(trace_, 1, 1);
  controls->setColumnStretch(2, 1);
  controls->addWidget(export_, 0, 3);
  auto* busy = new QHBoxLayout;
  busy->addWidget(progress_, 1);
  busy->addWidget(cancel_);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(2, 2, 2, 2);
  layout->addLayout(top);
  layout->addWidget(view_, 1);
  layout->addLayout(controls);
  layout->addLayout(busy);
  layout->addWidget(label_);

  connect(source_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this] {
    if (!filling_) onSourceChanged();
  });
  connect(measured_, &QCheckBox::toggled, this, &ArmPanel::onSourceChanged);
  connect(magnify_, QOverload<int>::of(&QSpinBox::valueChanged), this, [this](int m) {
    scene_->setMagnification(m);
    updateCaption();
    redraw();
  });
  connect(exaggerate_, QOverload<int>::of(&QSpinBox::valueChanged), this, [this](int e) {
    scene_->setExaggeration(e);
    updateCaption();
    redraw();
  });
  connect(ghost_, &QCheckBox::toggled, this, &ArmPanel::setGhostVisible);
  connect(trace_, &QCheckBox::toggled, this, &ArmPanel::setTraceVisible);
  connect(cancel_, &QToolButton::clicked, this, [this] {
    if (cancelFlag_) cancelFlag_->store(true);
  });
  connect(&watcher_, &QFutureWatcher<BodyAngles>::finished, this, &ArmPanel::onSimulated);
  connect(workspace_, &Workspace::logChanged, this, &ArmPanel::onLogChanged);
  // What another panel handed in as its result leaves with that result's record.
  connect(workspace_, &Workspace::resultWithdrawn, this, [this](const QString& key) {
    if (!faultKey_.isEmpty() && key == faultKey_) clearFault();
    if (external_ && !external_->resultKey.isEmpty() && key == external_->resultKey) clearExternalModel();
  });
  connect(workspace_, &Workspace::modelsChanged, this, [this](int index) {
    const int shown = source_->currentData().toInt();
    refillSources();
    if (index < 0 || index == shown) onSourceChanged();  // the model shown was edited
  });
  scene_->setMagnification(magnify_->value());
  refillSources();
  onLogChanged();
}

ArmPanel::~ArmPanel() {
  if (cancelFlag_) cancelFlag_->store(true);
  watcher_.waitForFinished();
}

void ArmPanel::setPlayhead(Playhead* playhead) {
  if (playhead_) disconnect(playhead_, nullptr, this, nullptr);
  playhead_ = playhead;
  if (playhead_) connect(playhead_, &Playhead::timeChanged, this, &ArmPanel::showTime);
  redraw();
}

QString ArmPanel::labelText() const { return label_->text(); }

int ArmPanel::magnification() const { return magnify_->value(); }
int ArmPanel::exaggeration() const { return exaggerate_->value(); }
void ArmPanel::setMagnification(int m) { magnify_->setValue(m); }
void ArmPanel::setExaggeration(int e) { exaggerate_->setValue(e); }

void ArmPanel::setGhostVisible(bool on) {
  if (ghost_->isChecked() != on) ghost_->setChecked(on);  // comes back here
  scene_->setGhostVisible(on && angles_ != nullptr);
  redraw();
}

void ArmPanel::setAnnotationsVisible(bool on) {
  overlay_.visible = on;
  view_->requestOverlay();
}

void ArmPanel::setTraceVisible(bool on) {
  if (trace_->isChecked() != on) trace_->setChecked(on);
  if (!on) scene_->setTrace({});
  redraw();
}

void ArmPanel::refillSources() {
  filling_ = true;
  const int was = source_->currentData().toInt();
  const QString wasName = source_->currentText();
  source_->clear();
  source_->addItem(tr("Log: motor angle, rigid"), kLogSource);
  const auto& models = workspace_->models();
  for (std::size_t i = 0; i < models.size(); ++i)
    if (models[i].model)
      source_->addItem((models[i].fitRequest ? tr("Fit: %1") : tr("Model: %1")).arg(nameOf(models[i])),
                       static_cast<int>(i));
  if (external_) source_->addItem(external_->name, kExternalSource);
  int at = source_->findText(wasName);
  if (at < 0) at = source_->findData(was);
  source_->setCurrentIndex(std::max(0, at));
  filling_ = false;
}

bool ArmPanel::selectModel(int index) { return selectSource(index < 0 ? kLogSource : index); }

bool ArmPanel::selectSource(int data) {
  const int at = source_->findData(data);
  if (at < 0) return false;
  if (source_->currentIndex() == at) onSourceChanged();  // recompute on request
  else source_->setCurrentIndex(at);
  return true;
}

void ArmPanel::setExternalModel(const QString& name, std::shared_ptr<const PhysicalModel> model,
                                std::vector<Effect> effects, const QString& resultKey) {
  if (!model || (!resultKey.isEmpty() && !workspace_->hasResult(resultKey))) {
    clearExternalModel();
    return;
  }
  external_ = External{name, resultKey, std::move(model), std::move(effects)};
  refillSources();
  selectSource(kExternalSource);
}

void ArmPanel::clearExternalModel() {
  if (!external_) return;
  const bool shown = source_->currentData().toInt() == kExternalSource;
  external_.reset();
  refillSources();
  if (shown) onSourceChanged();
}

void ArmPanel::onLogChanged() {
  const IdData* d = workspace_->raw();
  gearRatio_ = d ? gearRatioOf(*d) : 1.0 / 118.0;
  armMeanFor_ = nullptr;  // another log: its own encoder offset
  measured_->setEnabled(d && d->channel(columns::kMotorAngle));
  // Auto magnification: the log's largest motion about axis one drawn at about 35 degrees.
  if (const Channel* angle = d ? d->channel(columns::kMotorAngle) : nullptr) {
    const auto [lo, hi] = std::minmax_element(angle->values.begin(), angle->values.end());
    magnify_->setValue(niceDown(kMotionDrawn / (gearRatio_ * std::max(1e-12, *hi - *lo)), 1, 100000));
  }
  onSourceChanged();
}

void ArmPanel::onSourceChanged() {
  ++generation_;  // a result still on its way is for an older choice
  if (cancelFlag_) cancelFlag_->store(true);
  angles_.reset();
  scene_->setSprings(0);
  scene_->setGhostVisible(false);
  const int source = source_->currentData().toInt();
  if (source != kLogSource && workspace_->raw()) startSimulation();
  placeParameterFault();
  updateCaption();
  redraw();
}

void ArmPanel::startSimulation() {
  const int source = source_->currentData().toInt();
  std::shared_ptr<const PhysicalModel> model;
  std::vector<Effect> effects;
  if (source == kExternalSource && external_) {
    model = external_->model;
    effects = external_->effects;
    computingName_ = external_->name;
  } else if (source >= 0 && source < static_cast<int>(workspace_->models().size())) {
    const ModelEntry& e = workspace_->models()[static_cast<std::size_t>(source)];
    model = e.model;
    effects = e.effects;
    computingName_ = (e.fitRequest ? tr("%1 (fit)") : tr("%1 (model list)")).arg(nameOf(e));
  }
  if (!model) return;
  // The worker reads its own copy of the log: the workspace may replace it meanwhile.
  IdData data = *workspace_->raw();
  BodyAnglesOptions options;
  options.motorAngle = measured_->isChecked() ? MotorAngleSource::Measured : MotorAngleSource::Simulated;
  auto cancel = std::make_shared<std::atomic<bool>>(false);
  cancelFlag_ = cancel;
  simGeneration_ = generation_;
  progress_->setValue(0);
  progress_->setVisible(true);
  cancel_->setVisible(true);
  QPointer<QProgressBar> bar = progress_;
  watcher_.setFuture(QtConcurrent::run([model, effects, data = std::move(data), options, cancel, bar]() {
    int shown = -1;
    auto progress = [&](double f, const std::string&) {
      const int v = static_cast<int>(1000 * f);
      if (v - shown >= 10) {
        shown = v;
        QMetaObject::invokeMethod(bar, [bar, v] { if (bar) bar->setValue(v); }, Qt::QueuedConnection);
      }
      return cancel->load() ? ProgressAction::Abort : ProgressAction::Continue;
    };
    try {
      return simulateBodyAngles(*model, effects, data, options, progress);
    } catch (const std::exception& e) {
      BodyAngles failed;
      failed.message = e.what();
      return failed;
    }
  }));
}

void ArmPanel::onSimulated() {
  BodyAngles result = watcher_.result();
  progress_->setVisible(false);
  cancel_->setVisible(false);
  // The watcher reports only its latest simulation, but the source may have changed to one
  // that needs none since it started: then this result is for an old choice.
  if (simGeneration_ != generation_ || result.termination == Termination::Cancelled) {
    updateCaption();
    return;
  }
  const bool ok = result.termination == Termination::Converged;
  if (ok) {
    angles_ = std::make_shared<const BodyAngles>(std::move(result));
    scene_->setSprings(angles_->springs);
    const double largest = angles_->maxGearDeflection + angles_->maxArmDeflection;
    scene_->setDeflectionRange(std::max({angles_->maxGearDeflection, angles_->maxArmDeflection,
                                         angles_->maxParallelDeflection}));
    // The exaggeration shows the flexing of most of the log, not only of its largest moment.
    const double scale = std::min(kDeflectionDrawn / std::max(1e-12, medianDeflection(*angles_)),
                                  kDeflectionMost / std::max(1e-12, largest));
    exaggerate_->setValue(niceNearest(scale, 1, 1000000));
    scene_->setGhostVisible(ghost_->isChecked());
    placeParameterFault();
  }
  updateCaption();
  if (!ok) {
    label_->setText(tr("%1: %2 The arm plays rigidly.")
                        .arg(computingName_, QString::fromStdString(result.message)));
  }
  redraw();
  emit anglesReady(ok, ok ? QString::fromStdString(angles_->message)
                          : QString::fromStdString(result.message));
}

void ArmPanel::updateCaption() {
  const IdData* d = workspace_->raw();
  const bool angle = d && d->channel(columns::kMotorAngle);
  QString text;
  if (angles_) {
    text = tr("Angles: %1, simulated on the log's torque; motor angle %2")
               .arg(computingName_, QString::fromStdString(toString(angles_->motorAngleSource)));
    text += tr("\nmotion x%1, deflections x%2 (true size: %3 mrad at most); ghost: rigid arm")
                .arg(magnify_->value())
                .arg(exaggerate_->value())
                .arg(1e3 * std::max(angles_->maxGearDeflection, angles_->maxArmDeflection), 0, 'g', 3);
  } else if (isComputing()) {
    text = tr("Angles: the log's motor angle, rigid (simulating %1...)").arg(computingName_);
    text += tr("\nmotion x%1").arg(magnify_->value());
  } else if (angle) {
    text = tr("Angles: the log's motor angle through the gear, rigid (no model)");
    text += tr("\nmotion x%1").arg(magnify_->value());
  } else {
    text = d ? tr("The log has no motor angle: choose a model to simulate on its torque")
             : tr("No log: drag to rotate, wheel to zoom, double click to reset");
  }
  if (fault_) text += tr("\nFault: %1 (%2 in red)").arg(faultReason_, toString(*fault_));
  sourceText_ = text.section('\n', 0, 0);
  label_->setText(sourceText_);
  overlay_.caption = text;
  overlay_.legend = angles_ && angles_->springs > 0;
  overlay_.maxDeflection = scene_->deflectionRange();
  view_->requestOverlay();
}

BodyPose ArmPanel::poseAt(double t) const {
  if (angles_ && angles_->samples() > 0) return angles_->atTime(t);
  BodyPose p;
  const IdData* d = workspace_->raw();
  const Channel* angle = d ? d->channel(columns::kMotorAngle) : nullptr;
  if (!angle || angle->values.empty()) return p;
  const double pos = std::round((t - d->startTime) / d->sampleTime);
  const auto i = static_cast<std::size_t>(
      std::clamp(pos, 0.0, static_cast<double>(angle->values.size() - 1)));
  p.motor = angle->values[i];
  p.gearInput = p.gear = p.arm = p.parallel = gearRatio_ * p.motor;
  return p;
}

void ArmPanel::redraw() {
  // Settings changed: show the same time again even though the pose did not change.
  scene_->markChanged();
  showTime(playhead_ ? playhead_->time() : shownTime_);
}

void ArmPanel::showTime(double t) {
  shownTime_ = t;
  const IdData* d = workspace_->raw();
  const BodyPose pose = poseAt(t);
  if (!scene_->setPose(pose)) return;  // nothing changed: no render
  if (trace_->isChecked() && d && (angles_ || d->channel(columns::kMotorAngle))) {
    std::vector<BodyPose> history(kTracePoints);
    for (int j = 0; j < kTracePoints; ++j)
      history[static_cast<std::size_t>(j)] =
          poseAt(t - kTraceSeconds * (kTracePoints - 1 - j) / (kTracePoints - 1));
    scene_->setTrace(history);
  }
  QString status;
  if (d && (angles_ || d->channel(columns::kMotorAngle))) {
    status = tr("t = %1 s   motor %2 rad   arm %3 mrad")
                 .arg(t, 0, 'f', 3)
                 .arg(fixed(pose.motor, 4))
                 .arg(fixed(1e3 * pose.arm, 3));
    if (angles_ && angles_->springs >= 1)
      status += tr("\nr phi_m - phi_g %1 mrad").arg(mrad(pose.gearDeflection));
    if (angles_ && angles_->springs >= 2)
      status += tr("   phi_g - phi_a %1 mrad").arg(mrad(pose.armDeflection));
    if (angles_ && angles_->springs >= 3)
      status += tr("   phi_g - phi_p %1 mrad").arg(mrad(pose.parallelDeflection));
    status += measuredArmText(t, pose);
  }
  overlay_.status = status;
  view_->requestRender();
}

QString ArmPanel::measuredArmText(double t, const BodyPose& pose) {
  const IdData* d = workspace_->raw();
  const Channel* arm = d ? d->channel(columns::kArmAngle) : nullptr;
  const Channel* motor = d ? d->channel(columns::kMotorAngle) : nullptr;
  if (!arm || !motor || arm->values.empty() || arm->values.size() != motor->values.size()) return {};
  // The encoders' zeros are unrelated: the measured deflection is shown about its mean.
  if (armMeanFor_ != d || armMeanRatio_ != gearRatio_) {
    double sum = 0.0;
    for (std::size_t i = 0; i < arm->values.size(); ++i) sum += gearRatio_ * motor->values[i] - arm->values[i];
    armMean_ = sum / static_cast<double>(arm->values.size());
    armMeanFor_ = d;
    armMeanRatio_ = gearRatio_;
  }
  const double pos = std::round((t - d->startTime) / d->sampleTime);
  const auto i = static_cast<std::size_t>(std::clamp(pos, 0.0, static_cast<double>(arm->values.size() - 1)));
  const double measured = gearRatio_ * motor->values[i] - arm->values[i] - armMean_;
  QString text = tr("\narm encoder phi_a %1 mrad (shown: %2 mrad)   r phi_m - phi_a measured %3 mrad")
                     .arg(fixed(1e3 * arm->values[i], 3))
                     .arg(fixed(1e3 * pose.arm, 3))
                     .arg(mrad(measured));
  if (angles_ && angles_->springs >= 1)
    text += tr(", model %1 mrad").arg(mrad(pose.gearDeflection + (angles_->springs >= 2 ? pose.armDeflection : 0.0)));
  return text;
}

void ArmPanel::showFault(ArmPart part, const QString& reason, const QString& resultKey) {
  if (!resultKey.isEmpty() && !workspace_->hasResult(resultKey)) return;  // not of the open data
  faultParameter_.clear();
  faultKey_ = resultKey;
  if (fault_) scene_->setHighlight(*fault_, false);
  fault_ = part;
  faultReason_ = reason;
  scene_->setHighlight(part, true);
  updateCaption();
  redraw();
}

bool ArmPanel::showParameterFault(const QString& parameter, const QString& reason, const QString& resultKey) {
  const auto part = armPartForParameter(shownStructure(), parameter.toStdString());
  if (!part || (!resultKey.isEmpty() && !workspace_->hasResult(resultKey))) return false;
  showFault(*part, reason, resultKey);
  faultParameter_ = parameter;
  return true;
}

std::string ArmPanel::shownStructure() const { return angles_ ? angles_->structure : "rigid"; }

void ArmPanel::placeParameterFault() {
  if (faultParameter_.isEmpty()) return;
  const auto part = armPartForParameter(shownStructure(), faultParameter_.toStdString());
  if (!part || part == fault_) return;
  const QString parameter = faultParameter_;
  showFault(*part, faultReason_, faultKey_);
  faultParameter_ = parameter;
}

void ArmPanel::clearFault() {
  faultParameter_.clear();
  faultKey_.clear();
  if (!fault_) return;
  scene_->clearHighlights();
  fault_.reset();
  faultReason_.clear();
  updateCaption();
  redraw();
}

QImage ArmPanel::renderAt(double t) {
  showTime(t);
  QImage image = view_->grabFramebuffer();
  return image;
}

void ArmPanel::saveStill() {
  QSettings settings;
  const QString path = QFileDialog::getSaveFileName(
      this, tr("Save the arm view"), settings.value("lastDir").toString() + "/arm.png",
      tr("PNG image (*.png)"));
  if (path.isEmpty()) return;
  QString problem;
  if (!saveImageFile(view_->grabFramebuffer(), path, "PNG", &problem))
    QMessageBox::warning(this, tr("Save still"), tr("Cannot write %1: %2").arg(path, problem));
}

void ArmPanel::askExportFrames() {
  const IdData* d = workspace_->raw();
  if (!d || !playhead_ || !playhead_->hasSpan()) {
    QMessageBox::information(this, tr("Export frames"), tr("Open a log first."));
    return;
  }
  QDialog dialog(this);
  dialog.setWindowTitle(tr("Export the animation as PNG frames"));
  auto* form = new QFormLayout(&dialog);
  auto* folder = new QLineEdit(QSettings().value("lastDir").toString() + "/arm_frames", &dialog);
  auto* browse = new QPushButton(tr("Browse..."), &dialog);
  connect(browse, &QPushButton::clicked, &dialog, [&] {
    const QString f = QFileDialog::getExistingDirectory(&dialog, tr("Folder for the frames"), folder->text());
    if (!f.isEmpty()) folder->setText(f);
  });
  auto* row = new QHBoxLayout;
  row->addWidget(folder, 1);
  row->addWidget(browse);
  auto number = [&](double v, double lo, double hi, const QString& suffix) {
    auto* s = new QDoubleSpinBox(&dialog);
    s->setDecimals(4);
    s->setRange(lo, hi);
    s->setValue(v);
    s->setSuffix(suffix);
    return s;
  };
  // By default the loop selection, else two seconds from the playhead.
  const auto sel = playhead_->selection();
  const double t0 = sel ? sel->first : playhead_->time();
  const double t1 = sel ? sel->second : std::min(playhead_->end(), playhead_->time() + 2.0);
  auto* from = number(t0, playhead_->start(), playhead_->end(), " s");
  auto* to = number(t1, playhead_->start(), playhead_->end(), " s");
  auto* fps = number(30, 1, 120, tr(" frames/s"));
  auto* speed = number(playhead_->speed(), Playhead::kMinSpeed, Playhead::kMaxSpeed, "");
  speed->setPrefix(QString::fromUtf8("\u00d7"));
  form->addRow(tr("Folder"), row);
  form->addRow(tr("From"), from);
  form->addRow(tr("To"), to);
  form->addRow(tr("Frame rate"), fps);
  form->addRow(tr("Speed (log time per video time)"), speed);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Ok | QDialogButtonBox::Cancel, &dialog);
  form->addRow(buttons);
  connect(buttons, &QDialogButtonBox::accepted, &dialog, &QDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, &dialog, &QDialog::reject);
  if (dialog.exec() != QDialog::Accepted) return;
  exportFrames(folder->text(), from->value(), to->value(), fps->value(), speed->value());
}

void ArmPanel::exportFrames(const QString& folder, double t0, double t1, double fps,
                            double speed, bool runFfmpeg) {
  if (exporting_) return;
  exporting_ = true;
  auto* exporter = new FrameExporter([this](double t) { return renderAt(t); }, folder,
                                     FrameExporter::frameTimes(t0, t1, fps, speed), fps,
                                     runFfmpeg, this);
  connect(exporter, &FrameExporter::finished, this, [this, exporter](bool ok, const QString& message) {
    exporting_ = false;
    exporter->deleteLater();
    redraw();  // back to the playhead's time
    label_->setText(message);
    emit exportFinished(ok, message);
  });
  exporter->start();
}

}  // namespace flexarm
