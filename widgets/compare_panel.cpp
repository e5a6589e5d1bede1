#include "widgets/compare_panel.h"

#include <QComboBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QListWidget>
#include <QSpinBox>
#include <QSplitter>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <map>
#include <qcustomplot.h>

#include "core/compare/compare.h"
#include "widgets/background_refresh.h"
#include "widgets/ident_data.h"
#include "widgets/plots/envelope_graph.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {
namespace {
const QColor kColors[] = {QColor(31, 119, 180), QColor(214, 39, 40), QColor(44, 160, 44),
                          QColor(148, 103, 189), QColor(255, 127, 14), QColor(23, 190, 207)};
}  // namespace

ComparePanel::ComparePanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), models_(new QListWidget(this)),
      range_(new QComboBox(this)), horizon_(new QSpinBox(this)), plot_(new QCustomPlot(this)), fit_(new QLabel(this)),
      cursor_(new PlayheadCursor(plot_, this)), deflection_(new QCustomPlot(this)),
      worker_(new BackgroundRefresh(this)) {
  setObjectName("comparePanel");
  models_->setObjectName("compareModelList");
  models_->setMaximumWidth(220);
  range_->setObjectName("compareRangeCombo");
  range_->setToolTip(tr("Range the models are simulated on and the fit (5.2) computed over"));
  range_->addItem(tr("Validation range"), static_cast<int>(RangeKind::Validation));
  range_->addItem(tr("Estimation range"), static_cast<int>(RangeKind::Estimation));
  horizon_->setObjectName("compareHorizonSpin");
  horizon_->setRange(0, kMaxCompareHorizon);
  horizon_->setSpecialValueText(tr("simulation"));
  horizon_->setSuffix(tr("-step prediction"));
  horizon_->setToolTip(tr("What each model's output is: its simulation from the input alone, or its k-step "
                          "prediction y(t | t - k) from the measured output k samples back (a black-box "
                          "model's noise model predicts; an output-error model predicts what it simulates)"));
  // A time plot with its legend above, no time before the range.
  auto timePlot = [this](QCustomPlot* plot, const char* name, int height, const QString& label) {
    plot->setObjectName(name);
    plot->setMinimumSize(320, height);
    plot->xAxis->setLabel(tr("time [s]"));
    plot->yAxis->setLabel(label);
    plot->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
    plot->legend->setVisible(true);
    plot->legend->setFont(QFont(font().family(), 8));
    placeLegendAbove(plot);
    PlotTools::install(plot)->limitAxisToData(plot->xAxis);
  };
  timePlot(plot_, "comparePlot", 220, tr("output"));
  fit_->setObjectName("compareFitLabel");
  fit_->setWordWrap(true);
  // The deflection between motor and arm, shown when the log has an arm-side encoder.
  timePlot(deflection_, "compareDeflectionPlot", 160, tr("r phi_m - phi_a [mrad]"));
  deflection_->setVisible(false);
  connect(plot_->xAxis, QOverload<const QCPRange&>::of(&QCPAxis::rangeChanged), deflection_,
          [this](const QCPRange& r) {
            if (deflection_->isVisible() && deflection_->xAxis->range() != r) {
              deflection_->xAxis->setRange(r);
              deflection_->replot();
            }
          });

  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Compare on"), this));
  top->addWidget(range_);
  top->addWidget(new QLabel(tr("Output"), this));
  top->addWidget(horizon_);
  top->addStretch(1);
  auto* split = new QSplitter(Qt::Horizontal, this);
  auto* plots = new QSplitter(Qt::Vertical, this);
  plots->addWidget(plot_);
  plots->addWidget(deflection_);
  plots->setStretchFactor(0, 3);
  plots->setStretchFactor(1, 2);
  split->addWidget(models_);
  split->addWidget(plots);
  split->setStretchFactor(1, 4);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(top);
  layout->addWidget(split, 1);
  layout->addWidget(fit_);

  connect(models_, &QListWidget::itemChanged, this, &ComparePanel::refresh);
  connect(range_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, &ComparePanel::refresh);
  connect(horizon_, QOverload<int>::of(&QSpinBox::valueChanged), this, &ComparePanel::refresh);
  connect(workspace_, &Workspace::modelsChanged, this, [this](int) { refillList(); });
  // Another log (or its preprocessing) changes which models are of the open data.
  connect(workspace_, &Workspace::currentChanged, this, &ComparePanel::refillList);
  connect(workspace_, &Workspace::rangesChanged, this, &ComparePanel::refresh);
  refillList();
}

void ComparePanel::refillList() {
  fillModelChecklist(models_, workspace_->models(), *workspace_);
  refresh();
}

void ComparePanel::setPlayhead(Playhead* playhead) { cursor_->setPlayhead(playhead); }

void ComparePanel::setModelShown(int index, bool shown) {
  if (index >= 0 && index < models_->count())
    models_->item(index)->setCheckState(shown ? Qt::Checked : Qt::Unchecked);
}

void ComparePanel::setHorizon(int samples) { horizon_->setValue(samples); }

void ComparePanel::setRangeKind(RangeKind kind) {
  range_->setCurrentIndex(range_->findData(static_cast<int>(kind)));
}

QString ComparePanel::fitText() const { return fit_->text(); }

bool ComparePanel::isBusy() const { return worker_->isBusy(); }

namespace {

// One curve of the plot, computed in the background: its envelope over the range shown.
struct Curve {
  QString name;
  QPen pen;
  std::shared_ptr<const EnvelopePyramid> envelope;
  double startTime = 0.0, sampleTime = 1.0;
  double lo = 0.0, hi = 0.0;
};

}  // namespace

struct CompareOutcome {
  std::vector<double> fits, fitsNrmse;
  bool velocity = false;  // the curves are the motor velocity
  std::vector<Curve> curves;
  // On a log with an arm-side encoder: the measured deflection r phi_m - phi_a and each
  // physical model's, about their means over the range (empty without the encoder).
  std::vector<Curve> deflection;
  QString text;
};

namespace {

// A curve of values over [startTime, startTime + (n - 1) sampleTime], drawn through its
// envelope; a deflection about its mean in mrad.
Curve curveOf(const Eigen::VectorXd& v, double startTime, double sampleTime, const QString& name, const QPen& pen,
              double scale = 1.0) {
  std::vector<double> values(v.data(), v.data() + v.size());
  for (double& x : values) x *= scale;
  Curve c;
  c.name = name;
  c.pen = pen;
  c.startTime = startTime;
  c.sampleTime = sampleTime;
  if (!values.empty()) {
    const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
    c.lo = *lo;
    c.hi = *hi;
  }
  c.envelope = std::make_shared<const EnvelopePyramid>(values);
  return c;
}

// Every checked model compared on the snapshot's data by core's runCompare (the comparison
// `flexarm compare`, the session part and the report make), so that the panel shows the fit
// the Fit panel and the command line give for the same model and range; then the curves.
CompareOutcome compareModels(const WorkspaceSnapshot& snapshot, const std::vector<ModelEntry>& list,
                             const std::vector<bool>& checked, RangeKind kind, int horizon,
                             const std::atomic<bool>& stop) {
  CompareOutcome out;
  if (!snapshot.data || !snapshot.data->input() || !snapshot.data->output()) {
    out.text = QObject::tr("Open a log with an input and an output channel first.");
    return out;
  }
  CompareRequest request;
  request.data = evaluationDataOf(snapshot);
  request.range = kind == RangeKind::Validation ? DataRange::Validation : DataRange::Estimation;
  request.horizon = horizon;
  std::vector<std::size_t> shown;  // list index of each compared model
  for (std::size_t i = 0; i < list.size(); ++i)
    if (checked[i]) {
      request.models.push_back(list[i].evaluated());
      shown.push_back(i);
    }
  CompareResult r;
  try {
    r = runCompare(request, [&stop](double, const std::string&) {
      return stop.load() ? ProgressAction::Abort : ProgressAction::Continue;
    });
  } catch (const std::invalid_argument& e) {
    out.text = QString::fromStdString(e.what());
    return out;
  }
  out.velocity = r.velocity;
  QStringList lines;
  for (const auto& line : r.lines()) lines << QString::fromStdString(line);
  out.text = lines.join("\n");
  if (!r.ok() && r.models.empty()) return out;
  for (std::size_t k = 0; k < r.models.size(); ++k) {
    const ComparedModel& m = r.models[k];
    const QColor color = kColors[shown[k] % 6];
    if (!m.compared() || !m.fit) {
      out.fits.push_back(std::nan(""));
      out.fitsNrmse.push_back(std::nan(""));
      continue;
    }
    out.fits.push_back(m.fit->percent.seed52);
    out.fitsNrmse.push_back(m.fit->percent.nrmse);
    const QString name = QString::fromStdString(m.name);
    // The fit % as MATLAB's compare labels it (NRMSE) beside the seed's (5.2), of the output
    // shown: simulated, or predicted k steps ahead.
    const QString how = horizon > 0 ? QObject::tr(" (%1-step)").arg(horizon) : QString();
    out.curves.push_back(curveOf(m.output, m.startTime, m.sampleTime,
                                 QObject::tr("%1%2: %3 % NRMSE, %4 % (5.2)")
                                     .arg(name, how)
                                     .arg(m.fit->percent.nrmse, 0, 'f', 1)
                                     .arg(m.fit->percent.seed52, 0, 'f', 1),
                                 QPen(color, 1.2)));
    if (m.deflection)
      out.deflection.push_back(curveOf(m.deflection->predicted, m.startTime, m.sampleTime,
                                       QObject::tr("%1: %2 % (5.2)").arg(name).arg(m.deflection->figure.percent.seed52, 0, 'f', 1),
                                       QPen(color, 1.2), 1e3));
  }
  const QPen measured(QColor(20, 20, 20), 1.0);
  out.curves.push_back(curveOf(r.measured, r.startTime, r.sampleTime, QObject::tr("measured"), measured));  // on top
  if (!out.deflection.empty() && r.measuredDeflection.size())
    out.deflection.push_back(curveOf(r.measuredDeflection, r.startTime, r.sampleTime, QObject::tr("measured"), measured, 1e3));
  return out;
}

}  // namespace

void ComparePanel::refresh() {
  std::vector<bool> checked;
  for (std::size_t i = 0; i < workspace_->models().size(); ++i) checked.push_back(isModelChecked(models_, i));
  const auto kind = static_cast<RangeKind>(range_->currentData().toInt());
  const int horizon = horizon_->value();
  fit_->setText(tr("Simulating..."));
  worker_->run([this, snapshot = snapshotOf(*workspace_), list = workspace_->models(), checked, kind,
                horizon](const std::atomic<bool>& stop) -> BackgroundRefresh::Apply {
    auto out = std::make_shared<CompareOutcome>(compareModels(snapshot, list, checked, kind, horizon, stop));
    return [this, out] { showOutcome(*out); };
  });
}

namespace {

// Draws curves in plot over their common time span and value range, through their envelopes.
void drawCurves(QCustomPlot* plot, const std::vector<Curve>& curves) {
  plot->clearGraphs();
  double t0 = HUGE_VAL, t1 = -HUGE_VAL, lo = HUGE_VAL, hi = -HUGE_VAL;
  for (const Curve& c : curves) {
    auto* g = plot->addGraph();
    g->setName(c.name);
    g->setPen(c.pen);
    if (c.envelope->size() == 0) continue;
    t0 = std::min(t0, c.startTime);
    t1 = std::max(t1, c.startTime + static_cast<double>(c.envelope->size() - 1) * c.sampleTime);
    lo = std::min(lo, c.lo);
    hi = std::max(hi, c.hi);
  }
  if (t1 > t0) plot->xAxis->setRange(t0, t1);
  if (hi >= lo) {
    const double pad = std::max(1e-12, 0.05 * (hi - lo));
    plot->yAxis->setRange(lo - pad, hi + pad);
  }
  // After the range is set, so each curve takes only the points of its visible range.
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const Curve& c = curves[i];
    new EnvelopeGraph(plot->graph(static_cast<int>(i)), c.envelope, c.startTime, c.sampleTime);
  }
  plot->replot();
}

}  // namespace

void ComparePanel::showOutcome(const CompareOutcome& out) {
  plot_->clearGraphs();
  fits_ = out.fits;
  fitsNrmse_ = out.fitsNrmse;
  plot_->yAxis->setLabel(outputAxisLabel(*workspace_, out.velocity));
  fit_->setText(out.text);
  drawCurves(plot_, out.curves);
  deflection_->setVisible(!out.deflection.empty());
  deflectionCurves_ = static_cast<int>(out.deflection.size());
  if (!out.deflection.empty()) drawCurves(deflection_, out.deflection);
}

}  // namespace flexarm
