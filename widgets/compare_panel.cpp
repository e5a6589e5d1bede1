#include "widgets/compare_panel.h"

#include <QComboBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QListWidget>
#include <QSplitter>
#include <QVBoxLayout>
#include <cmath>
#include <map>
#include <qcustomplot.h>

#include "widgets/ident_data.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {
namespace {
const QColor kColors[] = {QColor(31, 119, 180), QColor(214, 39, 40), QColor(44, 160, 44),
                          QColor(148, 103, 189), QColor(255, 127, 14), QColor(23, 190, 207)};
// At most this many points per curve are drawn (every k-th sample).
constexpr std::size_t kMaxPoints = 6000;
}  // namespace

ComparePanel::ComparePanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), models_(new QListWidget(this)),
      range_(new QComboBox(this)), plot_(new QCustomPlot(this)), fit_(new QLabel(this)),
      cursor_(new PlayheadCursor(plot_, this)) {
  setObjectName("comparePanel");
  models_->setObjectName("compareModelList");
  models_->setMaximumWidth(220);
  range_->setObjectName("compareRangeCombo");
  range_->addItem(tr("Validation range"), static_cast<int>(RangeKind::Validation));
  range_->addItem(tr("Estimation range"), static_cast<int>(RangeKind::Estimation));
  plot_->setObjectName("comparePlot");
  plot_->setMinimumSize(320, 220);
  plot_->xAxis->setLabel(tr("time [s]"));
  plot_->yAxis->setLabel(tr("output"));
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  plot_->legend->setVisible(true);
  plot_->legend->setFont(QFont(font().family(), 8));
  placeLegendAbove(plot_);
  PlotTools::install(plot_)->limitAxisToData(plot_->xAxis);  // no time before the range
  fit_->setObjectName("compareFitLabel");
  fit_->setWordWrap(true);

  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Compare on"), this));
  top->addWidget(range_);
  top->addStretch(1);
  auto* split = new QSplitter(Qt::Horizontal, this);
  split->addWidget(models_);
  split->addWidget(plot_);
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

void ComparePanel::refresh() {
  plot_->clearGraphs();
  fits_.clear();
  fitsNrmse_.clear();
  const auto& list = workspace_->models();
  // Models give the motor velocity (the fit pipeline's black-box estimates too, Section 5.2),
  // unless a physical model's output is the motor angle.
  bool velocity = false;
  for (std::size_t i = 0; i < list.size(); ++i)
    if (isModelChecked(models_, i)) velocity = velocity || wantsVelocity(list[i]);
  // The data at each rate a model needs (black-box models at the rate they were estimated at).
  std::map<int, std::optional<PreparedData>> rates;
  QString why;
  auto at = [&](int factor) -> const std::optional<PreparedData>& {
    auto it = rates.find(factor);
    if (it == rates.end()) it = rates.emplace(factor, workspaceData(*workspace_, factor, velocity, &why)).first;
    return it->second;
  };
  const auto kind = static_cast<RangeKind>(range_->currentData().toInt());
  auto rangeOf = [kind](const PreparedData& d) {
    const SampleRange r = kind == RangeKind::Validation ? d.validation : d.estimation;
    return r.empty() ? d.estimation : r;
  };
  auto addGraph = [&](const PreparedData& d, const Eigen::VectorXd& v, const QString& name,
                      const QPen& pen) {
    const SampleRange r = rangeOf(d);
    const std::size_t step = std::max<std::size_t>(1, r.size() / kMaxPoints);
    QVector<double> t, y;
    for (std::size_t i = r.begin; i < r.end; i += step) {
      t.push_back(d.startTime + static_cast<double>(i) * d.sampleTime);
      y.push_back(v[static_cast<Eigen::Index>(i)]);
    }
    auto* g = plot_->addGraph();
    g->setData(t, y, true);
    g->setName(name);
    g->setPen(pen);
  };
  plot_->yAxis->setLabel(outputAxisLabel(*workspace_, velocity));
  const auto& base = at(1);
  if (!base) {
    fit_->setText(why);
    plot_->replot();
    return;
  }
  const bool noValidation = kind == RangeKind::Validation && base->validation.empty();
  QStringList lines;
  int colour = 0;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const QColor color = kColors[colour++ % 6];
    if (!isModelChecked(models_, i)) continue;
    QString reason;
    std::optional<Eigen::VectorXd> sim;
    const int factor = decimationFor(list[i], base->sampleTime);
    const auto& data = factor > 0 ? at(factor) : base;
    try {
      if (factor == 0)
        reason = tr("its sample time is no multiple of the data's");
      else if (data)
        sim = simulateEntry(list[i], data->u, data->sampleTime, &reason);
    } catch (const std::exception& e) {
      reason = QString::fromStdString(e.what());
    }
    if (!sim || !sim->allFinite()) {
      fits_.push_back(std::nan(""));
      fitsNrmse_.push_back(std::nan(""));
      lines << tr("%1: not simulated (%2)").arg(list[i].name, reason.isEmpty() ? tr("unstable") : reason);
      continue;
    }
    const SampleRange r = rangeOf(*data);
    const FitPercents fit = fitPercents(data->y, *sim, static_cast<Eigen::Index>(r.begin),
                                        static_cast<Eigen::Index>(r.end));
    fits_.push_back(fit.seed52);
    fitsNrmse_.push_back(fit.nrmse);
    addGraph(*data, *sim, tr("%1: %2 % (5.2)").arg(list[i].name).arg(fit.seed52, 0, 'f', 1), QPen(color, 1.2));
    lines << tr("%1: fit %2 % (5.2), %3 % NRMSE%4").arg(list[i].name).arg(fit.seed52, 0, 'f', 1)
                 .arg(fit.nrmse, 0, 'f', 1)
                 .arg(factor > 1 ? tr(" (at %1 Hz)").arg(1.0 / data->sampleTime, 0, 'g', 4) : QString());
  }
  addGraph(*base, base->y, tr("measured"), QPen(QColor(20, 20, 20), 1.0));  // on top
  lines.prepend(tr("Fit of the simulated output on the %1 data (%2), as the seed's (5.2) "
                    "1 - sum e^2/sum (y - mean y)^2 and as MATLAB compare's NRMSE 1 - |e|/|y - mean y|:")
                    .arg(noValidation ? tr("estimation (no validation range set)")
                                      : kind == RangeKind::Validation ? tr("validation") : tr("estimation"),
                         QString::fromStdString(base->note())));
  fit_->setText(lines.join("\n"));
  plot_->rescaleAxes();
  plot_->replot();
}

}  // namespace flexarm
