#include "widgets/lqg_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QElapsedTimer>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QResizeEvent>
#include <QScrollBar>
#include <QScrollArea>
#include <QSplitter>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <algorithm>
#include <cmath>
#include <qcustomplot.h>
#include <tuple>

#include "core/models/two_mass_lqg_reduction.h"
#include "widgets/log_slider.h"
#include "widgets/plots/plot_tools.h"
#include "widgets/plots/pole_zero_plot.h"

namespace flexarm {
namespace {

const QColor kCurrent(31, 119, 180);
const QColor kPinned(255, 127, 14);
const QColor kComplementary(44, 160, 44);
const QColor kSaturated(214, 39, 40);
const QColor kAntiWindup(148, 103, 189);

// Above this cost (redesign plus drawing) a slider move is computed off the GUI thread and
// moves made meanwhile are coalesced into one redesign.
constexpr double kSynchronousBudget = 0.012;  // s
// Smallest plot of the grid: titles, legends and tick labels stay readable.
constexpr int kPlotMinimumWidth = 230, kPlotMinimumHeight = 210;

QVector<double> qv(const std::vector<double>& v) { return QVector<double>(v.begin(), v.end()); }

QString number(double v, int digits = 3) { return QString::number(v, 'g', digits); }

// A parametric curve (Nyquist): points in order of frequency.
void setCurve(QCPCurve* c, const std::vector<std::complex<double>>& pts, bool mirror) {
  QVector<double> t, x, y;
  t.reserve(static_cast<int>(pts.size()));
  x.reserve(static_cast<int>(pts.size()));
  y.reserve(static_cast<int>(pts.size()));
  for (std::size_t i = 0; i < pts.size(); ++i) {
    t.push_back(static_cast<double>(i));
    x.push_back(pts[i].real());
    y.push_back(mirror ? -pts[i].imag() : pts[i].imag());
  }
  c->setData(t, x, y, true);
}

// Zoom and drag, a title row above the axes and the legend in its own row below the title,
// never over the curves; at least as wide as the title.
void setUpPlot(QCustomPlot* p, const char* name, const QString& title) {
  p->setObjectName(name);
  p->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(p);
  p->legend->setVisible(true);
  p->legend->setFont(QFont(p->font().family(), 8));
  p->plotLayout()->insertRow(0);
  auto* text = new QCPTextElement(p, title, QFont(p->font().family(), 9, QFont::Bold));
  p->plotLayout()->addElement(0, 0, text);
  placeLegendAbove(p);
  p->setMinimumSize(std::max(kPlotMinimumWidth, QFontMetrics(text->font()).horizontalAdvance(title) + 24),
                    kPlotMinimumHeight);
}

QPen pen(const QColor& c, double width, bool dashed) {
  QPen p(c, width);
  if (dashed) p.setStyle(Qt::DashLine);
  return p;
}

}  // namespace

const char* toString(LqgPanel::Preset p) {
  switch (p) {
    case LqgPanel::Preset::CaseI:
      return "case-i";
    case LqgPanel::Preset::CaseII:
      return "case-ii";
    case LqgPanel::Preset::AccelerationFeedback:
      return "acceleration-feedback";
  }
  return "?";
}

LqgPanel::LqgPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), source_(new QComboBox(this)),
      reduction_(new QComboBox(this)), reductionLabel_(new QLabel(this)),
      acceleration_(new QCheckBox(tr("Measure the arm acceleration too (8.40)"), this)),
      saturation_(new QCheckBox(tr("Input saturation |u| <="), this)),
      saturationLimit_(new QLineEdit("2.5", this)),
      pinButton_(new QPushButton(tr("Pin design"), this)),
      unpinButton_(new QPushButton(tr("Unpin"), this)), badge_(new QLabel(this)),
      pinnedBadge_(new QLabel(this)), summary_(new QLabel(this)), nyquist_(new QCustomPlot(this)),
      sensitivity_(new QCustomPlot(this)), steps_(new QCustomPlot(this)),
      poles_(new PoleZeroPlot(this)), budget_(kSynchronousBudget) {
  setObjectName("lqgPanel");
  auto* box = new QWidget;
  buildControls(box);
  auto* scroll = new QScrollArea(this);
  scroll->setWidget(box);
  scroll->setWidgetResizable(true);

  badge_->setObjectName("stabilityBadge");
  pinnedBadge_->setObjectName("pinnedBadge");
  summary_->setObjectName("lqgSummary");
  summary_->setWordWrap(true);
  summary_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  for (QLabel* b : {badge_, pinnedBadge_}) {
    QFont f = b->font();
    f.setBold(true);
    b->setFont(f);
    b->setMargin(4);
    b->setMinimumWidth(80);  // a narrow dock wraps the sentence instead of widening the window
    b->setWordWrap(true);
  }
  pinnedBadge_->hide();

  // Nyquist of F_y G, zoomable, with -1 and the -1/Y_f line.
  setUpPlot(nyquist_, "nyquistPlot", tr("Nyquist of F_y G (8.6)"));
  nyquist_->xAxis->setLabel(tr("Re F_y G [-]"));
  nyquist_->yAxis->setLabel(tr("Im F_y G [-]"));
  // |S| and |T| on log axes.
  setUpPlot(sensitivity_, "sensitivityPlot", tr("|S| (8.36) and |T|"));
  sensitivity_->xAxis->setLabel(tr("frequency [rad/s]"));
  sensitivity_->yAxis->setLabel(tr("magnitude [-]"));
  for (QCPAxis* a : {sensitivity_->xAxis, sensitivity_->yAxis}) {
    a->setScaleType(QCPAxis::stLogarithmic);
    a->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
  }
  // Steps: arm angle on top, torque below.
  setUpPlot(steps_, "stepPlot", tr("Steps in w and v (Fig. 8.3)"));
  steps_->axisRect(0)->axis(QCPAxis::atBottom)->setLabel(tr("time [s]"));
  auto* torqueRect = new QCPAxisRect(steps_);
  steps_->plotLayout()->addElement(steps_->plotLayout()->rowCount(), 0, torqueRect);
  steps_->axisRect(0)->axis(QCPAxis::atLeft)->setLabel(tr("arm angle [rad]"));
  torqueRect->axis(QCPAxis::atLeft)->setLabel(tr("torque [N m]"));
  torqueRect->axis(QCPAxis::atBottom)->setLabel(tr("time [s]"));
  steps_->setMinimumHeight(kPlotMinimumHeight + 90);
  auto* group = new QCPMarginGroup(steps_);
  steps_->axisRect(0)->setMarginGroup(QCP::msLeft | QCP::msRight, group);
  torqueRect->setMarginGroup(QCP::msLeft | QCP::msRight, group);
  connect(steps_->axisRect(0)->axis(QCPAxis::atBottom),
          QOverload<const QCPRange&>::of(&QCPAxis::rangeChanged), torqueRect->axis(QCPAxis::atBottom),
          QOverload<const QCPRange&>::of(&QCPAxis::setRange));
  const QString polesTitle = tr("Regulator and closed-loop poles");
  auto* polesText = new QCPTextElement(poles_->plot(), polesTitle,
                                       QFont(font().family(), 9, QFont::Bold));
  poles_->plot()->plotLayout()->insertRow(0);
  poles_->plot()->plotLayout()->addElement(0, 0, polesText);
  poles_->setMinimumSize(
      std::max(kPlotMinimumWidth, QFontMetrics(polesText->font()).horizontalAdvance(polesTitle) + 24),
      kPlotMinimumHeight);

  auto* zoomNear = new QPushButton(tr("Nyquist near -1"), this);
  zoomNear->setObjectName("zoomNearMinusOne");
  auto* zoomWide = new QPushButton(tr("Nyquist wide"), this);
  zoomWide->setObjectName("zoomWide");
  connect(zoomNear, &QPushButton::clicked, this, &LqgPanel::zoomNearMinusOne);
  connect(zoomWide, &QPushButton::clicked, this, &LqgPanel::showWholeNyquist);
  controlsButton_ = new QPushButton(tr("Hide controls"), this);
  controlsButton_->setObjectName("controlsToggle");
  controlsButton_->setToolTip(tr("Hide or show the design controls to give the plots the room"));
  connect(controlsButton_, &QPushButton::clicked, this,
          [this] { setControlsShown(!controlsShown()); });
  zoomNear->setToolTip(tr("Zoom the Nyquist plot around -1, where stability margins show"));
  zoomWide->setToolTip(tr("Show the whole Nyquist curve"));
  // Buttons in one row, the verdicts (whole sentences, wrapped) in the next.
  auto* buttonRow = new QHBoxLayout;
  buttonRow->addWidget(controlsButton_);
  buttonRow->addStretch(1);
  buttonRow->addWidget(zoomNear);
  buttonRow->addWidget(zoomWide);
  auto* badgeRow = new QHBoxLayout;
  badgeRow->addWidget(badge_, 1);
  badgeRow->addWidget(pinnedBadge_, 1);
  auto* grid = new QGridLayout;
  plotGrid_ = grid;
  arrangePlots(1);  // compact until shown: reflow() widens to two columns when there is room
  auto* right = new QWidget(this);
  auto* rightLayout = new QVBoxLayout(right);
  rightLayout->setContentsMargins(0, 0, 0, 0);
  rightLayout->addLayout(buttonRow);
  rightLayout->addLayout(badgeRow);
  rightLayout->addLayout(grid, 1);
  rightLayout->addWidget(summary_);
  auto* split = new QSplitter(Qt::Horizontal, this);
  // Nothing of the controls hides behind the scroll bar: the side is as wide as the controls
  // plus the bar; a short dock scrolls them.
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  scroll->setMinimumWidth(box->minimumSizeHint().width() +
                          scroll->verticalScrollBar()->sizeHint().width() + 2 * scroll->frameWidth());
  controlsSide_ = scroll;
  split->addWidget(scroll);
  split->addWidget(right);
  split->setStretchFactor(0, 0);
  split->setStretchFactor(1, 1);
  split_ = split;
  controls_ = box;
  connect(split, &QSplitter::splitterMoved, this, [this] { splitterMoved_ = true; });
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(4, 4, 4, 4);
  layout->addWidget(split);

  connect(&watcher_, &QFutureWatcher<std::shared_ptr<const LqgAnalysis>>::finished, this, [this] {
    QElapsedTimer t;
    t.start();
    const auto a = watcher_.result();
    showAnalysis(a);
    lastCost_ = a->seconds + t.nsecsElapsed() * 1e-9;
    inFlight_ = false;
    if (pending_) {
      pending_ = false;
      requestUpdate();
    }
  });
  connect(workspace_, &Workspace::modelsChanged, this, [this](int index) {
    const int selected = source_->currentIndex();
    refreshSources();
    if (selected > 0 && (index < 0 || index == selected - 1)) selectSource(source_->currentIndex());
  });
  refreshSources();
  fillParameters(parameters_);
  applyPreset(Preset::CaseI);
  zoomNearMinusOne();
}

LqgPanel::~LqgPanel() { watcher_.waitForFinished(); }

bool LqgPanel::eventFilter(QObject* watched, QEvent* e) {
  // In a dock the panel sits in a scroll area: the room it has is the viewport's width.
  if (watched == parentWidget() && e->type() == QEvent::Resize) reflow();
  return QWidget::eventFilter(watched, e);
}

void LqgPanel::showEvent(QShowEvent* e) {
  QWidget::showEvent(e);
  if (parentWidget() && !filtering_) {
    parentWidget()->installEventFilter(this);
    filtering_ = true;
  }
  reflow();
}

void LqgPanel::reflow() {
  // Controls beside the plots when both fit side by side, else above them (a narrow dock
  // scrolls down instead of hiding half the panel to the right).
  const bool inScroll = parentWidget() && parentWidget()->objectName() == "qt_scrollarea_viewport";
  const int room = inScroll ? parentWidget()->width() : width();
  const int plotWidth = std::max(nyquist_->minimumWidth(), poles_->minimumWidth());
  const Qt::Orientation wanted =
      !controlsShown() || room >= controlsSide_->minimumWidth() + plotWidth + 24 ? Qt::Horizontal
                                                                                 : Qt::Vertical;
  if (split_->orientation() != wanted) {
    split_->setOrientation(wanted);
    splitterMoved_ = false;
  }
  QResizeEvent again(size(), size());
  resizeEvent(&again);
}

void LqgPanel::resizeEvent(QResizeEvent* e) {
  QWidget::resizeEvent(e);
  if (split_->orientation() == Qt::Vertical) {
    if (!splitterMoved_ && controlsShown()) {
      const int total = split_->height();
      const int top = std::min(controlsSide_->sizeHint().height(), std::max(160, total * 2 / 5));
      split_->setSizes({top, total - top});
    }
    const int twoColumns = 2 * std::max(nyquist_->minimumWidth(), poles_->minimumWidth()) + 12;
    arrangePlots(split_->width() >= twoColumns ? 2 : 1);
    return;
  }
  const int total = split_->width();
  if (!splitterMoved_ && controlsShown()) {
    const int left = std::max(controlsSide_->minimumWidth(),
                              std::min(controlsSide_->sizeHint().width() + 20, total * 2 / 5));
    split_->setSizes({left, total - left});
  }
  const int plotsWidth = controlsShown() ? total - split_->sizes().value(0) : total;
  const int twoColumns = 2 * std::max(nyquist_->minimumWidth(), poles_->minimumWidth()) + 12;
  arrangePlots(plotsWidth >= twoColumns ? 2 : 1);
}

void LqgPanel::arrangePlots(int columns) {
  if (columns == plotColumns_) return;
  plotColumns_ = columns;
  QWidget* const plots[] = {nyquist_, sensitivity_, steps_, poles_};
  for (QWidget* p : plots) plotGrid_->removeWidget(p);
  for (int i = 0; i < 4; ++i) plotGrid_->addWidget(plots[i], i / columns, i % columns);
}

bool LqgPanel::controlsShown() const { return controlsSide_ && !controlsSide_->isHidden(); }

void LqgPanel::setControlsShown(bool shown) {
  controlsSide_->setVisible(shown);
  controlsButton_->setText(shown ? tr("Hide controls") : tr("Show controls"));
  reflow();
}

void LqgPanel::buildControls(QWidget* box) {
  auto* layout = new QVBoxLayout(box);

  auto* plant = new QGroupBox(tr("Two-mass arm (8.1)-(8.6)"), box);
  auto* plantLayout = new QGridLayout(plant);
  source_->setObjectName("plantSource");
  source_->setToolTip(tr("Table 8.1, or a model of the shared list reduced to the two-mass form"));
  reduction_->setObjectName("reductionMethod");
  for (auto r : {TwoMassReduction::MatchFirstMode, TwoMassReduction::MergeMasses})
    reduction_->addItem(toString(r));
  reduction_->setToolTip(
      tr("How a three- or four-mass model becomes two masses: match the first antiresonance and "
         "resonance keeping the total inertia, or merge the masses after the gear with the "
         "springs in series. Two-mass models are scaled by r^2 exactly."));
  reductionLabel_->setObjectName("reductionLabel");
  reductionLabel_->setWordWrap(true);
  plantLayout->addWidget(new QLabel(tr("Plant"), plant), 0, 0);
  plantLayout->addWidget(source_, 0, 1, 1, 3);
  plantLayout->addWidget(new QLabel(tr("Reduction"), plant), 1, 0);
  plantLayout->addWidget(reduction_, 1, 1, 1, 3);
  plantLayout->addWidget(reductionLabel_, 2, 0, 1, 4);
  const auto& names = TwoMassLqgParameters::names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    const QString name = QString::fromStdString(names[i]);
    auto* edit = new QLineEdit(plant);
    edit->setObjectName("param_" + name);
    edit->setToolTip(QString::fromStdString(TwoMassLqgParameters::unit(names[i])));
    connect(edit, &QLineEdit::editingFinished, this, &LqgPanel::onParameterEdited);
    params_.push_back(edit);
    const int row = 3 + static_cast<int>(i) / 2, col = 2 * (static_cast<int>(i) % 2);
    plantLayout->addWidget(new QLabel(name, plant), row, col);
    plantLayout->addWidget(edit, row, col + 1);
  }
  layout->addWidget(plant);

  auto* presets = new QGroupBox(tr("Seed designs (Section 8.3, 8.7)"), box);
  auto* presetLayout = new QHBoxLayout(presets);
  for (auto [p, text, tip] :
       {std::tuple{Preset::CaseI, tr("Case (i)"), tr("R2 = 1e-6: stable regulator")},
        std::tuple{Preset::CaseII, tr("Case (ii)"), tr("R2 = 1e-8: unstable regulator")},
        std::tuple{Preset::AccelerationFeedback, tr("Acc. feedback"),
                   tr("arm acceleration measured, R2 = diag(1e-8, 1e-1)")}}) {
    auto* b = new QPushButton(text, presets);
    b->setObjectName(QString("preset_") + toString(p));
    b->setToolTip(tip + tr("; Q1 = diag(100, 1, 0, 0, 0), Q2 = 1, R1 = diag(0, 0, 0, 0, 1)"));
    const Preset preset = p;
    connect(b, &QPushButton::clicked, this, [this, preset] { applyPreset(preset); });
    presetLayout->addWidget(b);
  }
  layout->addWidget(presets);

  auto* weights = new QGroupBox(tr("Weights (8.17) and covariances"), box);
  auto* weightLayout = new QVBoxLayout(weights);
  const QStringList states = {"phi_m", "phi_m'", "phi_a", "phi_a'", "x5 load"};
  auto add = [&](const QString& name, const QString& label, double lo, double hi, int steps,
                 bool zero) {
    auto* s = new LogSlider(name, label, lo, hi, steps, zero, weights);
    connect(s, &LogSlider::valueChanged, this, [this] { requestUpdate(); });
    weights_.push_back(s);
    weightLayout->addWidget(s);
  };
  for (int i = 0; i < 5; ++i)
    add(QString("q1_%1").arg(i + 1), tr("Q1 %1").arg(states[i]), 1e-4, 1e4, 10, true);
  add("q2", tr("Q2"), 1e-4, 1e4, 10, false);
  for (int i = 0; i < 5; ++i)
    add(QString("r1_%1").arg(i + 1), tr("R1 %1").arg(states[i]), 1e-6, 1e4, 10, true);
  add("r2_1", tr("R2 phi_m"), 1e-12, 1.0, 20, false);
  add("r2_2", tr("R2 phi_a''"), 1e-6, 1e2, 10, false);
  layout->addWidget(weights);

  auto* options = new QGroupBox(tr("Measurement and saturation"), box);
  auto* optionLayout = new QGridLayout(options);
  acceleration_->setObjectName("accelerationFeedback");
  acceleration_->setToolTip(tr("Measure the arm acceleration besides the motor angle (8.40); "
                               "its noise weight is R2 phi_a''"));
  saturation_->setObjectName("saturation");
  saturation_->setToolTip(tr("Simulate the steps with the torque limited to the value beside"));
  saturationLimit_->setObjectName("saturationLimit");
  saturationLimit_->setToolTip(tr("torque limit in N m; the steps are also simulated saturated, "
                                  "without and with anti-windup (8.31)-(8.32)"));
  optionLayout->addWidget(acceleration_, 0, 0, 1, 2);
  optionLayout->addWidget(saturation_, 1, 0);
  optionLayout->addWidget(saturationLimit_, 1, 1);
  connect(acceleration_, &QCheckBox::toggled, this, [this] {
    updateMeasurementControls();
    requestUpdate();
  });
  connect(saturation_, &QCheckBox::toggled, this, [this] { requestUpdate(); });
  connect(saturationLimit_, &QLineEdit::editingFinished, this, [this] { requestUpdate(); });
  layout->addWidget(options);

  pinButton_->setObjectName("pinButton");
  unpinButton_->setObjectName("unpinButton");
  pinButton_->setToolTip(tr("Keep the current design overlaid in every plot to compare"));
  unpinButton_->setEnabled(false);
  unpinButton_->setToolTip(tr("Remove the pinned design from the plots"));
  connect(pinButton_, &QPushButton::clicked, this, &LqgPanel::pin);
  connect(unpinButton_, &QPushButton::clicked, this, &LqgPanel::unpin);
  auto* pinRow = new QHBoxLayout;
  pinRow->addWidget(pinButton_);
  pinRow->addWidget(unpinButton_);
  layout->addLayout(pinRow);
  layout->addStretch(1);

  connect(source_, QOverload<int>::of(&QComboBox::activated), this, &LqgPanel::selectSource);
  connect(reduction_, QOverload<int>::of(&QComboBox::activated), this,
          [this] { selectSource(source_->currentIndex()); });
}

void LqgPanel::refreshSources() {
  const int keep = source_->currentIndex();
  source_->blockSignals(true);
  source_->clear();
  source_->addItem(tr("Table 8.1 (seed)"));
  for (const auto& m : workspace_->models()) source_->addItem(tr("model: %1").arg(nameOf(m)));
  source_->setCurrentIndex(std::clamp(keep, 0, source_->count() - 1));
  source_->blockSignals(false);
}

void LqgPanel::selectSource(int index) {
  if (index < 0 || index >= source_->count()) return;
  source_->setCurrentIndex(index);
  if (index == 0) {
    reductionLabel_->setText(tr("Table 8.1: the seed's arm, arm side scaled to the motor."));
    fillParameters(TwoMassLqgParameters{});
    requestUpdate();
    return;
  }
  const ModelEntry& entry = workspace_->models()[static_cast<std::size_t>(index - 1)];
  if (!entry.model) {
    reductionLabel_->setText(tr("Cannot use %1: a black-box estimate has no physical "
                                "parameters to reduce. The parameters stay.").arg(nameOf(entry)));
    return;
  }
  TwoMassReductionOptions o;
  o.method = twoMassReductionFromString(reduction_->currentText().toStdString())
                 .value_or(TwoMassReduction::MatchFirstMode);
  const TwoMassReductionResult r = reduceToTwoMass(*entry.model, o);
  if (!r.ok()) {
    reductionLabel_->setText(tr("Cannot use %1: %2. The parameters stay.")
                                 .arg(nameOf(entry), QString::fromStdString(r.message)));
    return;
  }
  reductionLabel_->setText(QString::fromStdString(r.message) + tr(" (f_a = 0)."));
  fillParameters(r.parameters);
  requestUpdate();
}

void LqgPanel::fillParameters(const TwoMassLqgParameters& p) {
  parameters_ = p;
  const auto& names = TwoMassLqgParameters::names();
  for (std::size_t i = 0; i < names.size(); ++i) {
    params_[i]->setText(QString::number(p.get(names[i]), 'g', 5));
    params_[i]->setStyleSheet(QString());
  }
}

void LqgPanel::onParameterEdited() {
  auto* edit = qobject_cast<QLineEdit*>(sender());
  if (!edit) return;
  const std::string name = edit->objectName().mid(6).toStdString();
  bool ok = false;
  const double v = edit->text().trimmed().toDouble(&ok);
  TwoMassLqgParameters p = parameters_;
  std::string why = "'" + edit->text().toStdString() + "' is not a number";
  if (ok) p.set(name, v);
  if (!ok || !p.isValid(&why)) {
    edit->setStyleSheet("background: #fbd5d5");
    edit->setToolTip(QString::fromStdString(why));
    edit->setText(QString::number(parameters_.get(name), 'g', 5));
    return;
  }
  edit->setStyleSheet(QString());
  edit->setToolTip(QString::fromStdString(TwoMassLqgParameters::unit(name)));
  if (p.get(name) == parameters_.get(name)) return;
  parameters_ = p;
  requestUpdate();
}

void LqgPanel::updateMeasurementControls() {
  weight("r2_2")->setEnabled(acceleration_->isChecked());
}

LogSlider* LqgPanel::weight(const QString& name) const {
  for (LogSlider* s : weights_)
    if (s->objectName() == name) return s;
  return nullptr;
}

LqgOptions LqgPanel::options() const {
  LqgOptions o;
  o.parameters = parameters_;
  o.measurement = acceleration_->isChecked() ? LqgMeasurement::MotorAngleAndArmAcceleration
                                             : LqgMeasurement::MotorAngle;
  o.integralAction = true;
  for (int i = 0; i < 5; ++i) {
    o.q1(i) = weight(QString("q1_%1").arg(i + 1))->value();
    o.r1(i) = weight(QString("r1_%1").arg(i + 1))->value();
  }
  o.q2 = weight("q2")->value();
  o.r2.resize(o.measurements());
  o.r2(0) = weight("r2_1")->value();
  if (o.measurements() > 1) o.r2(1) = weight("r2_2")->value();
  return o;
}

LqgAnalysisOptions LqgPanel::analysisOptions() const {
  LqgAnalysisOptions ao;
  ao.taBandwidth = 0.0;  // the Section 8.4 check depends on the plant only (flexarm lqg has it)
  bool ok = false;
  const double limit = saturationLimit_->text().toDouble(&ok);
  if (saturation_->isChecked() && ok && std::isfinite(limit) && limit > 0.0)
    ao.saturationLimit = limit;
  return ao;
}

void LqgPanel::applyPreset(Preset preset) {
  const LqgOptions o = preset == Preset::CaseI    ? LqgOptions::seedCaseI()
                       : preset == Preset::CaseII ? LqgOptions::seedCaseII()
                                                  : LqgOptions::seedAccelerationFeedback();
  quiet_ = true;
  for (int i = 0; i < 5; ++i) {
    weight(QString("q1_%1").arg(i + 1))->setValue(o.q1(i));
    weight(QString("r1_%1").arg(i + 1))->setValue(o.r1(i));
  }
  weight("q2")->setValue(o.q2);
  weight("r2_1")->setValue(o.r2(0));
  if (o.r2.size() > 1) weight("r2_2")->setValue(o.r2(1));
  acceleration_->setChecked(o.measurement == LqgMeasurement::MotorAngleAndArmAcceleration);
  updateMeasurementControls();
  quiet_ = false;
  requestUpdate();
}

void LqgPanel::setDesign(const LqgOptions& o, double saturationLimit, const QString& source) {
  quiet_ = true;
  source_->blockSignals(true);
  source_->setCurrentIndex(0);
  for (int i = 1; i < source_->count(); ++i)
    if (source_->itemText(i) == source) source_->setCurrentIndex(i);
  source_->blockSignals(false);
  reductionLabel_->setText(tr("Parameters as the session stored them (%1).").arg(source));
  fillParameters(o.parameters);
  for (int i = 0; i < 5 && i < o.q1.size() && i < o.r1.size(); ++i) {
    weight(QString("q1_%1").arg(i + 1))->setValue(o.q1(i));
    weight(QString("r1_%1").arg(i + 1))->setValue(o.r1(i));
  }
  weight("q2")->setValue(o.q2);
  if (o.r2.size() > 0) weight("r2_1")->setValue(o.r2(0));
  if (o.r2.size() > 1) weight("r2_2")->setValue(o.r2(1));
  acceleration_->setChecked(o.measurement == LqgMeasurement::MotorAngleAndArmAcceleration);
  saturation_->setChecked(saturationLimit > 0.0);
  if (saturationLimit > 0.0) saturationLimit_->setText(QString::number(saturationLimit, 'g', 6));
  updateMeasurementControls();
  quiet_ = false;
  requestUpdate();
}

QString LqgPanel::sourceText() const { return source_->currentText(); }
QString LqgPanel::tableSourceText() const { return source_->itemText(0); }

void LqgPanel::requestUpdate() {
  if (quiet_) return;
  const LqgOptions o = options();
  const LqgAnalysisOptions ao = analysisOptions();
  std::string why;
  if (!o.isValid(&why) || !ao.isValid(&why)) {
    showFailure(tr("cannot design: %1").arg(QString::fromStdString(why)));
    return;
  }
  if (inFlight_) {
    pending_ = true;  // the newest settings are read when the running redesign ends
    return;
  }
  if (lastCost_ >= budget_) {
    startBackground();
    return;
  }
  QElapsedTimer t;
  t.start();
  showAnalysis(std::make_shared<const LqgAnalysis>(analyzeLqg(o, ao)));
  lastCost_ = t.nsecsElapsed() * 1e-9;
}

void LqgPanel::startBackground() {
  const LqgOptions o = options();
  const LqgAnalysisOptions ao = analysisOptions();
  pending_ = false;
  inFlight_ = true;
  watcher_.setFuture(QtConcurrent::run(
      [o, ao]() { return std::make_shared<const LqgAnalysis>(analyzeLqg(o, ao)); }));
}

void LqgPanel::showFailure(const QString& why) {
  badge_->setText(why);
  badge_->setStyleSheet("background: #dddddd; color: #333333; border-radius: 4px;");
}

void LqgPanel::showAnalysis(std::shared_ptr<const LqgAnalysis> a) {
  current_ = std::move(a);
  if (!current_->ok()) {
    showFailure(tr("the design failed: %1").arg(QString::fromStdString(current_->message)));
    return;
  }
  const LqgDesign& d = current_->design;
  badge_->setText(QString::fromStdString(d.regulatorStability()));
  badge_->setStyleSheet(d.rhpRegulatorPoles == 0
                            ? "background: #c9ecc9; color: #135813; border-radius: 4px;"
                            : "background: #f6c4c4; color: #8a1111; border-radius: 4px;");
  QElapsedTimer drawing;
  drawing.start();
  redraw();
  const double drawSeconds = drawing.nsecsElapsed() * 1e-9;
  const LqgAnalysis& c = *current_;
  QString text =
      tr("F_y G encircles -1 %1 times counter-clockwise (P - Z = %2); max |S| = %3 at %4 rad/s, "
         "min distance to -1 = %5; Bode's integral (8.37) %6 vs pi sum Re(p_i) = %7; peak arm "
         "deviation %8 rad; closed loop %9; redesign %10 ms, plot data %11 ms.")
          .arg(c.loop.encirclements)
          .arg(c.expectedEncirclements)
          .arg(number(c.maxSensitivity))
          .arg(number(c.maxSensitivityFrequency))
          .arg(number(c.minDistanceToMinusOne))
          .arg(number(c.bodeIntegral, 4))
          .arg(number(c.bodePrediction, 4))
          .arg(number(c.steps.peakArmDeviation))
          .arg(d.rhpClosedLoopPoles == 0 ? tr("stable") : tr("UNSTABLE"))
          .arg(c.seconds * 1e3, 0, 'f', 2)
          .arg(drawSeconds * 1e3, 0, 'f', 2);
  if (!c.saturated.time.empty())
    text += tr(" Saturated: peak %1 rad%2 without anti-windup, %3 rad%4 with; F_y G meets "
               "-1/Y_f %5 times, G_0 (8.35) %6 times.")
                .arg(number(c.saturated.peakArmDeviation))
                .arg(c.saturated.diverged ? tr(" (diverged)") : QString())
                .arg(number(c.saturatedAntiWindup.peakArmDeviation))
                .arg(c.saturatedAntiWindup.diverged ? tr(" (diverged)") : QString())
                .arg(c.loopCrossings.size())
                .arg(c.g0Crossings.size());
  summary_->setText(text);
  emit analysed();
}

void LqgPanel::pin() {
  if (!current_ || !current_->ok()) return;
  pinned_ = current_;
  const LqgOptions o = options();
  pinnedLabel_ = tr("pinned (R2 = %1)").arg(number(o.r2(0)));
  pinnedBadge_->setText(tr("%1: %2").arg(pinnedLabel_,
                                         QString::fromStdString(pinned_->design.regulatorStability())));
  pinnedBadge_->setStyleSheet(QString("border: 2px dashed %1; border-radius: 4px;").arg(kPinned.name()));
  pinnedBadge_->show();
  unpinButton_->setEnabled(true);
  redraw();
}

void LqgPanel::unpin() {
  pinned_.reset();
  pinnedBadge_->hide();
  unpinButton_->setEnabled(false);
  redraw();
}

void LqgPanel::redraw() {
  // Nyquist: positive frequencies solid, negative (mirror) dotted, pinned dashed.
  const double xLow = nyquist_->xAxis->range().lower, xHigh = nyquist_->xAxis->range().upper;
  const double yLow = nyquist_->yAxis->range().lower, yHigh = nyquist_->yAxis->range().upper;
  nyquist_->clearPlottables();
  nyquist_->clearItems();
  QCustomPlot* s = sensitivity_;
  s->clearGraphs();
  s->clearItems();
  steps_->clearGraphs();
  poles_->clear();
  QCPAxisRect* armRect = steps_->axisRect(0);
  QCPAxisRect* torqueRect = steps_->axisRect(1);

  struct Shown {
    const LqgAnalysis* a;
    QString name;
    QColor color;
    bool dashed;
  };
  std::vector<Shown> shown;
  std::vector<QCPGraph*> unscaled;  // diverged runs leave the view instead of flattening it
  if (pinned_) shown.push_back({pinned_.get(), pinnedLabel_, kPinned, true});
  if (current_ && current_->ok()) shown.push_back({current_.get(), tr("current"), kCurrent, false});

  for (const Shown& e : shown) {
    const LqgAnalysis& a = *e.a;
    auto* pos = new QCPCurve(nyquist_->xAxis, nyquist_->yAxis);
    setCurve(pos, a.loop.values, false);
    pos->setPen(pen(e.color, e.dashed ? 1.6 : 1.8, e.dashed));
    pos->setName(tr("%1, %2 turns").arg(e.name).arg(a.loop.encirclements));
    auto* neg = new QCPCurve(nyquist_->xAxis, nyquist_->yAxis);
    setCurve(neg, a.loop.values, true);
    QPen mirror(e.color.lighter(140), 1, Qt::DotLine);
    neg->setPen(mirror);
    neg->removeFromLegend();

    auto* sg = s->addGraph();
    sg->setData(qv(a.loop.frequencies), qv(a.sensitivity), true);
    sg->setPen(pen(e.color, 1.8, e.dashed));
    sg->setName(tr("|S| %1, max %2").arg(e.name, number(a.maxSensitivity)));
    auto* tg = s->addGraph();
    tg->setData(qv(a.loop.frequencies), qv(a.complementary), true);
    tg->setPen(pen(e.dashed ? kComplementary.lighter(130) : kComplementary, 1.4, e.dashed));
    tg->setName(tr("|T| %1").arg(e.name));

    auto* arm = steps_->addGraph(armRect->axis(QCPAxis::atBottom), armRect->axis(QCPAxis::atLeft));
    arm->setData(qv(a.steps.time), qv(a.steps.armAngle), true);
    arm->setPen(pen(e.color, 1.6, e.dashed));
    arm->setName(tr("phi_a %1, peak %2").arg(e.name, number(a.steps.peakArmDeviation)));
    auto* torque =
        steps_->addGraph(torqueRect->axis(QCPAxis::atBottom), torqueRect->axis(QCPAxis::atLeft));
    torque->setData(qv(a.steps.time), qv(a.steps.torque), true);
    torque->setPen(pen(e.color, 1.4, e.dashed));
    torque->removeFromLegend();
    if (!e.dashed && !a.saturated.time.empty()) {
      for (auto [r, color, label] :
           {std::tuple{&a.saturated, kSaturated, tr("saturated")},
            std::tuple{&a.saturatedAntiWindup, kAntiWindup, tr("saturated, anti-windup")}}) {
        auto* g = steps_->addGraph(armRect->axis(QCPAxis::atBottom), armRect->axis(QCPAxis::atLeft));
        std::vector<double> arms = r->armAngle;  // a diverged run is cut where it leaves the view
        for (double& v : arms) v = std::clamp(v, -1e3, 1e3);
        g->setData(qv(r->time), qv(arms), true);
        g->setPen(QPen(color, 1.2));
        g->setName(label + (r->diverged ? tr(" (diverged)") : QString()));
        if (r->diverged) unscaled.push_back(g);
        auto* u = steps_->addGraph(torqueRect->axis(QCPAxis::atBottom),
                                   torqueRect->axis(QCPAxis::atLeft));
        u->setData(qv(r->time), qv(r->torque), true);
        u->setPen(QPen(color, 1.0));
        u->removeFromLegend();
      }
    }

    std::vector<std::complex<double>> reg(a.design.regulatorPoles.data(),
                                          a.design.regulatorPoles.data() +
                                              a.design.regulatorPoles.size());
    poles_->addSet(tr("regulator %1").arg(e.name), e.color, reg, {});
  }
  if (current_ && current_->ok()) {
    const auto& cl = current_->design.closedLoopPoles;
    std::vector<std::complex<double>> closed(cl.data(), cl.data() + cl.size());
    poles_->addSet(tr("closed loop"), QColor(150, 150, 150), closed, {});
  }
  // Zoom the pole map on the regulator poles (closed-loop poles reach far left).
  {
    double re = 1.0, im = 1.0;
    for (const Shown& e : shown)
      for (Eigen::Index i = 0; i < e.a->design.regulatorPoles.size(); ++i) {
        re = std::max(re, std::abs(e.a->design.regulatorPoles(i).real()));
        im = std::max(im, std::abs(e.a->design.regulatorPoles(i).imag()));
      }
    poles_->plot()->xAxis->setRange(-1.15 * re, std::max(0.3 * re, 10.0));
    poles_->plot()->yAxis->setRange(-1.15 * im, 1.15 * im);
  }

  // The -1 point, and -1/Y_f (8.30) from -1 to the left when saturation is on.
  auto* minusOne = new QCPGraph(nyquist_->xAxis, nyquist_->yAxis);
  minusOne->setData(QVector<double>{-1.0}, QVector<double>{0.0});
  minusOne->setLineStyle(QCPGraph::lsNone);
  minusOne->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssPlus, QPen(Qt::red, 2), Qt::NoBrush, 12));
  minusOne->setName("-1");
  if (current_ && current_->ok() && !current_->saturated.time.empty()) {
    auto* line = new QCPItemLine(nyquist_);
    line->start->setCoords(-1.0, 0.0);
    line->end->setCoords(-1e9, 0.0);
    line->setPen(QPen(kSaturated, 3));
    auto* label = new QCPItemText(nyquist_);
    label->position->setCoords(-1.2, -0.08);
    label->setPositionAlignment(Qt::AlignRight | Qt::AlignTop);
    label->setText(tr("-1/Y_f (8.30) "));
    label->setColor(kSaturated);
    std::vector<double> x, y;
    for (const auto& c : current_->loopCrossings) {
      x.push_back(c.realPart);
      y.push_back(0.0);
    }
    auto* cross = new QCPGraph(nyquist_->xAxis, nyquist_->yAxis);
    cross->setData(qv(x), qv(y));
    cross->setLineStyle(QCPGraph::lsNone);
    cross->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssCircle, QPen(kSaturated, 2), Qt::NoBrush, 10));
    cross->setName(tr("meets -1/Y_f"));
  }
  nyquist_->xAxis->setRange(xLow, xHigh);
  nyquist_->yAxis->setRange(yLow, yHigh);

  // |S| = 1 for reference and the maximum of the current |S|.
  auto* one = new QCPItemStraightLine(s);
  one->point1->setCoords(1.0, 1.0);
  one->point2->setCoords(10.0, 1.0);
  one->setPen(QPen(QColor(120, 120, 120), 1, Qt::DashLine));
  if (!shown.empty()) {
    const auto& f = shown.back().a->loop.frequencies;
    s->xAxis->setRange(std::max(f.front(), 1e-1), std::min(f.back(), 1e4));
    s->yAxis->setRange(1e-3, 20.0);
  }
  armRect->axis(QCPAxis::atBottom)->setRange(0.0, 3.0);
  for (QCPAxisRect* r : {armRect, torqueRect}) {
    bool found = false;
    QCPRange range;
    for (QCPGraph* g : r->graphs()) {
      if (std::find(unscaled.begin(), unscaled.end(), g) != unscaled.end()) continue;
      bool ok = false;
      const QCPRange gr = g->getValueRange(ok);
      if (!ok) continue;
      range = found ? QCPRange(std::min(range.lower, gr.lower), std::max(range.upper, gr.upper)) : gr;
      found = true;
    }
    if (found) {
      const double pad = 0.08 * std::max(range.size(), 1e-9);
      r->axis(QCPAxis::atLeft)->setRange(range.lower - pad, range.upper + pad);
    }
  }
  for (QCustomPlot* p : {nyquist_, sensitivity_, steps_, poles_->plot()})
    p->replot(QCustomPlot::rpQueuedReplot);
}

void LqgPanel::zoomNearMinusOne() {
  nyquist_->xAxis->setRange(-4.0, 2.0);
  nyquist_->yAxis->setRange(-3.0, 3.0);
  nyquist_->replot(QCustomPlot::rpQueuedReplot);
}

void LqgPanel::showWholeNyquist() {
  // The loop gain grows without bound at low frequency (integral action): show the part
  // with |F_y G| <= 50, which holds every encirclement of -1.
  double x0 = -2, x1 = 1, y0 = -1, y1 = 1;
  auto take = [&](const LqgAnalysis* a) {
    if (!a) return;
    for (const auto& v : a->loop.values)
      if (std::abs(v) <= 50.0) {
        x0 = std::min(x0, v.real());
        x1 = std::max(x1, v.real());
        y0 = std::min(y0, -std::abs(v.imag()));
        y1 = std::max(y1, std::abs(v.imag()));
      }
  };
  take(current_.get());
  take(pinned_.get());
  nyquist_->xAxis->setRange(x0 - 0.5, x1 + 0.5);
  nyquist_->yAxis->setRange(y0 - 0.5, y1 + 0.5);
  nyquist_->replot(QCustomPlot::rpQueuedReplot);
}

QString LqgPanel::badgeText() const { return badge_->text(); }
QString LqgPanel::pinnedBadgeText() const { return pinned_ ? pinnedBadge_->text() : QString(); }
QString LqgPanel::summaryText() const { return summary_->text(); }
QString LqgPanel::reductionText() const { return reductionLabel_->text(); }

std::vector<std::complex<double>> LqgPanel::nyquistPoints() const {
  // Read back from the drawn curve of the current design (the last curve pair added).
  std::vector<std::complex<double>> out;
  QCPCurve* drawn = nullptr;
  for (int i = 0; i < nyquist_->plottableCount(); ++i)
    if (auto* c = qobject_cast<QCPCurve*>(nyquist_->plottable(i)))
      if (c->pen().color() == kCurrent && c->pen().style() == Qt::SolidLine) drawn = c;
  if (!drawn) return out;
  for (const auto& d : *drawn->data()) out.emplace_back(d.key, d.value);
  return out;
}

}  // namespace flexarm
