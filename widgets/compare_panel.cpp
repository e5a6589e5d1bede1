#include "widgets/compare_panel.h"

#include <QComboBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QListWidget>
#include <QSplitter>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <map>
#include <qcustomplot.h>

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
      range_(new QComboBox(this)), plot_(new QCustomPlot(this)), fit_(new QLabel(this)),
      cursor_(new PlayheadCursor(plot_, this)), deflection_(new QCustomPlot(this)),
      worker_(new BackgroundRefresh(this)) {
  setObjectName("comparePanel");
  models_->setObjectName("compareModelList");
  models_->setMaximumWidth(220);
  range_->setObjectName("compareRangeCombo");
  range_->setToolTip(tr("Range the models are simulated on and the fit (5.2) computed over"));
  range_->addItem(tr("Validation range"), static_cast<int>(RangeKind::Validation));
  range_->addItem(tr("Estimation range"), static_cast<int>(RangeKind::Estimation));
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
  connect(workspace_, &Workspace::modelsChanged, this, [this](int) { refillList(); });
  for (auto sig : {&Workspace::currentChanged, &Workspace::rangesChanged})
    connect(workspace_, sig, this, &ComparePanel::refresh);
  refillList();
}

void ComparePanel::refillList() {
  fillModelChecklist(models_, workspace_->models());
  refresh();
}

void ComparePanel::setPlayhead(Playhead* playhead) { cursor_->setPlayhead(playhead); }

void ComparePanel::setModelShown(int index, bool shown) {
  if (index >= 0 && index < models_->count())
    models_->item(index)->setCheckState(shown ? Qt::Checked : Qt::Unchecked);
}

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



// Simulates every checked model on the snapshot's data and forms the fit (5.2) of each on
// the range of `kind`: the whole of the work that grows with the log.
CompareOutcome compareModels(const WorkspaceSnapshot& snapshot, const std::vector<ModelEntry>& list,
                      const std::vector<bool>& checked, RangeKind kind,
                      const std::atomic<bool>& stop) {
  CompareOutcome out;
  // Models give the motor velocity (the fit pipeline's black-box estimates too, Section 5.2),
  // unless a physical model's output is the motor angle.
  bool velocity = false;
  for (std::size_t i = 0; i < list.size(); ++i)
    if (checked[i]) velocity = velocity || wantsVelocity(list[i]);
  // The data at each rate a model needs (black-box models at the rate they were estimated at).
  std::map<int, std::optional<PreparedData>> rates;
  QString why;
  auto at = [&](int factor) -> const std::optional<PreparedData>& {
    auto it = rates.find(factor);
    if (it == rates.end()) it = rates.emplace(factor, workspaceData(snapshot, factor, velocity, &why)).first;
    return it->second;
  };
  auto rangeOf = [kind](const PreparedData& d) {
    const SampleRange r = kind == RangeKind::Validation ? d.validation : d.estimation;
    return r.empty() ? d.estimation : r;
  };
  // A deflection curve is drawn about its mean over the range, in mrad.
  auto addCurve = [&](const PreparedData& d, const Eigen::VectorXd& v, const QString& name, const QPen& pen,
                      std::vector<Curve>* to = nullptr, bool deflection = false) {
    const SampleRange r = rangeOf(d);
    std::vector<double> values(v.data() + r.begin, v.data() + r.end);
    if (deflection && !values.empty()) {
      double mean = 0.0;
      for (double x : values) mean += x;
      mean /= static_cast<double>(values.size());
      for (double& x : values) x = 1e3 * (x - mean);
    }
    Curve c;
    c.name = name;
    c.pen = pen;
    c.startTime = d.timeAt(r.begin);
    c.sampleTime = d.sampleTime;
    if (!values.empty()) {
      const auto [lo, hi] = std::minmax_element(values.begin(), values.end());
      c.lo = *lo;
      c.hi = *hi;
    }
    c.envelope = std::make_shared<const EnvelopePyramid>(values);
    (to ? *to : out.curves).push_back(std::move(c));
  };
  out.velocity = velocity;
  const auto& base = at(1);
  if (!base) {
    out.text = why;
    return out;
  }
  const bool noValidation = kind == RangeKind::Validation && base->validation.empty();
  QStringList lines, deflection;
  int colour = 0;
  // The deflection the encoders measure, through the log's gear ratio (else the first
  // physical model's r), when the log has an arm-side encoder.
  double ratio = std::nan("");
  if (const auto stated = logGearRatio(*snapshot.data)) ratio = *stated;
  for (std::size_t i = 0; i < list.size() && std::isnan(ratio); ++i)
    if (checked[i] && list[i].model) ratio = list[i].model->value("r");
  const Eigen::VectorXd measured = std::isnan(ratio) ? Eigen::VectorXd() : measuredDeflection(*base, ratio);
  for (std::size_t i = 0; i < list.size() && !stop.load(); ++i) {
    const QColor color = kColors[colour++ % 6];
    if (!checked[i]) continue;
    QString reason;
    std::optional<Eigen::VectorXd> sim;
    const int factor = decimationFor(list[i], base->sampleTime);
    const auto& data = factor > 0 ? at(factor) : base;
    try {
      if (factor == 0)
        reason = QObject::tr("its sample time is no multiple of the data's");
      else if (data)
        sim = simulateEntry(list[i], data->u, data->sampleTime, &reason);
    } catch (const std::exception& e) {
      reason = QString::fromStdString(e.what());
    }
    if (!sim || !sim->allFinite()) {
      out.fits.push_back(std::nan(""));
      out.fitsNrmse.push_back(std::nan(""));
      lines << QObject::tr("%1: not simulated (%2)")
                   .arg(list[i].name, reason.isEmpty() ? QObject::tr("unstable") : reason);
      continue;
    }
    const SampleRange r = rangeOf(*data);
    const FitPercents fit = fitPercents(data->y, *sim, static_cast<Eigen::Index>(r.begin),
                                        static_cast<Eigen::Index>(r.end));
    out.fits.push_back(fit.seed52);
    out.fitsNrmse.push_back(fit.nrmse);
    addCurve(*data, *sim, QObject::tr("%1: %2 % (5.2)").arg(list[i].name).arg(fit.seed52, 0, 'f', 1),
             QPen(color, 1.2));
    if (measured.size() && list[i].model && &data == &base) {
      const Eigen::VectorXd predicted =
          simulateDeflection(*list[i].model, data->u, data->sampleTime, encoderSkewOf(list[i].effects));
      const SampleRange r2 = rangeOf(*data);
      const auto b = static_cast<Eigen::Index>(r2.begin), n = static_cast<Eigen::Index>(r2.size());
      const Eigen::VectorXd m = measured.segment(b, n).array() - measured.segment(b, n).mean();
      const Eigen::VectorXd p = predicted.segment(b, n).array() - predicted.segment(b, n).mean();
      const FitPercents df = fitPercents(m, p);
      addCurve(*data, predicted, QObject::tr("%1: %2 % (5.2)").arg(list[i].name).arg(df.seed52, 0, 'f', 1),
               QPen(color, 1.2), &out.deflection, true);
      deflection << QObject::tr("%1: deflection %2 % (5.2), %3 % NRMSE")
                        .arg(list[i].name)
                        .arg(df.seed52, 0, 'f', 1)
                        .arg(df.nrmse, 0, 'f', 1);
    }
    lines << QObject::tr("%1: fit %2 % (5.2), %3 % NRMSE%4").arg(list[i].name).arg(fit.seed52, 0, 'f', 1)
                 .arg(fit.nrmse, 0, 'f', 1)
                 .arg(factor > 1 ? QObject::tr(" (at %1 Hz)").arg(1.0 / data->sampleTime, 0, 'g', 4) : QString());
  }
  addCurve(*base, base->y, QObject::tr("measured"), QPen(QColor(20, 20, 20), 1.0));  // on top
  if (!out.deflection.empty()) {
    addCurve(*base, measured, QObject::tr("measured"), QPen(QColor(20, 20, 20), 1.0), &out.deflection, true);
    lines << QObject::tr("The deflection r phi_m - phi_a the arm-side encoder measures (r = %1), predicted from "
                         "the torque by each model's linear part (with its encoder_skew), each about its mean:")
                 .arg(ratio, 0, 'g', 6)
          << deflection;
  }
  lines.prepend(QObject::tr("Fit of the simulated output on the %1 data (%2), as the seed's (5.2) "
                            "1 - sum e^2/sum (y - mean y)^2 and as MATLAB compare's NRMSE 1 - |e|/|y - mean y|:")
                    .arg(noValidation ? QObject::tr("estimation (no validation range set)")
                                      : kind == RangeKind::Validation ? QObject::tr("validation")
                                                                      : QObject::tr("estimation"),
                         QString::fromStdString(base->note())));
  out.text = lines.join("\n");
  return out;
}

}  // namespace

void ComparePanel::refresh() {
  std::vector<bool> checked;
  for (std::size_t i = 0; i < workspace_->models().size(); ++i) checked.push_back(isModelChecked(models_, i));
  const auto kind = static_cast<RangeKind>(range_->currentData().toInt());
  fit_->setText(tr("Simulating..."));
  worker_->run([this, snapshot = snapshotOf(*workspace_), list = workspace_->models(), checked,
                kind](const std::atomic<bool>& stop) -> BackgroundRefresh::Apply {
    auto out = std::make_shared<CompareOutcome>(compareModels(snapshot, list, checked, kind, stop));
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
