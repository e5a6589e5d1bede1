#include "widgets/residuals_panel.h"

#include <QComboBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QSpinBox>
#include <QVBoxLayout>
#include <qcustomplot.h>

#include "core/compare/residual_study.h"
#include "widgets/background_refresh.h"
#include "widgets/ident_data.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {
namespace {

void setupPlot(QCustomPlot* p, const QString& title, const QString& xLabel) {
  p->setMinimumSize(300, 160);
  PlotTools::install(p);
  p->plotLayout()->insertRow(0);
  p->plotLayout()->addElement(0, 0, new QCPTextElement(p, title, QFont("sans", 9, QFont::Bold)));
  p->xAxis->setLabel(xLabel);
  p->yAxis->setLabel(QObject::tr("correlation [-]"));
}

// Correlations as bars with the +-bound band drawn as dashed lines.
void showCorrelation(QCustomPlot* p, const std::vector<int>& lags, const std::vector<double>& r,
          double bound, int firstTested) {
  p->clearPlottables();
  p->clearItems();
  auto* inside = new QCPBars(p->xAxis, p->yAxis);
  auto* outside = new QCPBars(p->xAxis, p->yAxis);
  inside->setBrush(QColor(31, 119, 180));
  inside->setPen(Qt::NoPen);
  outside->setBrush(QColor(214, 39, 40));
  outside->setPen(Qt::NoPen);
  for (std::size_t i = 0; i < lags.size(); ++i) {
    const bool out = lags[i] >= firstTested && std::abs(r[i]) > bound;
    (out ? outside : inside)->addData(lags[i], r[i]);
  }
  for (QCPBars* b : {inside, outside}) b->setWidth(0.6);
  for (double level : {bound, -bound}) {
    auto* line = new QCPItemStraightLine(p);
    line->point1->setCoords(0, level);
    line->point2->setCoords(1, level);
    line->setPen(QPen(QColor(200, 40, 40), 1, Qt::DashLine));
  }
  p->rescaleAxes();
  const double top = std::max(1.2 * bound, p->yAxis->range().upper);
  const double bottom = std::min(-1.2 * bound, p->yAxis->range().lower);
  p->yAxis->setRange(bottom, top);
  p->xAxis->setRange(lags.front() - 1, lags.back() + 1);
  p->replot();
}

}  // namespace

ResidualsPanel::ResidualsPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), model_(new QComboBox(this)),
      range_(new QComboBox(this)), lags_(new QSpinBox(this)), auto_(new QCustomPlot(this)),
      cross_(new QCustomPlot(this)), verdict_(new QLabel(this)),
      worker_(new BackgroundRefresh(this)) {
  setObjectName("residualsPanel");
  model_->setObjectName("residualsModelCombo");
  range_->setObjectName("residualsRangeCombo");
  model_->setToolTip(tr("Model whose residuals are tested: prediction errors (4.5) of a black box, "
                        "output errors of a physical model"));
  range_->setToolTip(tr("Range the residuals are computed on (the validation range tests the model "
                        "on data it was not fitted to)"));
  range_->addItem(tr("Estimation range"), static_cast<int>(RangeKind::Estimation));
  range_->addItem(tr("Validation range"), static_cast<int>(RangeKind::Validation));
  lags_->setObjectName("residualsLagSpin");
  lags_->setRange(5, 500);
  lags_->setValue(25);
  lags_->setToolTip(tr("Largest lag M of the correlations"));
  auto_->setObjectName("autocorrelationPlot");
  cross_->setObjectName("crossCorrelationPlot");
  setupPlot(auto_, tr("Autocorrelation of residuals (99 % bounds)"),
             tr("lag [samples]"));
  setupPlot(cross_, tr("Cross-correlation of input and residuals (99 % bounds)"),
             tr("lag [samples]"));
  verdict_->setObjectName("residualsVerdict");
  verdict_->setWordWrap(true);

  auto* top = new QHBoxLayout;
  top->addWidget(new QLabel(tr("Model"), this));
  top->addWidget(model_, 1);
  top->addWidget(range_);
  top->addWidget(new QLabel(tr("Lags"), this));
  top->addWidget(lags_);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(top);
  layout->addWidget(auto_, 1);
  layout->addWidget(cross_, 1);
  layout->addWidget(verdict_);

  connect(model_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this] {
    if (!filling_) refresh();
  });
  connect(range_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, &ResidualsPanel::refresh);
  connect(lags_, QOverload<int>::of(&QSpinBox::valueChanged), this, &ResidualsPanel::refresh);
  connect(workspace_, &Workspace::modelsChanged, this, [this](int) { refillList(); });
  connect(workspace_, &Workspace::currentChanged, this, &ResidualsPanel::refillList);
  connect(workspace_, &Workspace::rangesChanged, this, &ResidualsPanel::refresh);
  refillList();
}

void ResidualsPanel::refillList() {
  filling_ = true;
  const QString keep = model_->currentText();
  model_->clear();
  const auto& models = workspace_->models();
  int newestOwn = -1;  // default: the newest model of the open data, else the newest
  for (std::size_t i = 0; i < models.size(); ++i) {
    model_->addItem(nameOf(models[i]));
    model_->setItemData(static_cast<int>(i), QString::fromStdString(models[i].provenanceText()), Qt::ToolTipRole);
    if (ofOpenData(models[i], *workspace_)) newestOwn = static_cast<int>(i);
  }
  // The model shown stays, unless another log made it a model of other data.
  int k = model_->findText(keep);
  if (k >= 0 && newestOwn >= 0 && !ofOpenData(models[static_cast<std::size_t>(k)], *workspace_)) k = -1;
  model_->setCurrentIndex(k >= 0 ? k : newestOwn >= 0 ? newestOwn : model_->count() - 1);
  filling_ = false;
  refresh();
}

void ResidualsPanel::selectModel(int index) { model_->setCurrentIndex(index); }
void ResidualsPanel::setRangeKind(RangeKind kind) {
  range_->setCurrentIndex(range_->findData(static_cast<int>(kind)));
}
void ResidualsPanel::setMaxLag(int lags) { lags_->setValue(lags); }
QString ResidualsPanel::verdictText() const { return verdict_->text(); }

bool ResidualsPanel::isBusy() const { return worker_->isBusy(); }

namespace {

// The correlation tests of one model on the snapshot's data by core's runResiduals (the
// analysis `flexarm residuals`, the session part and the report make). Sets analysis (empty
// lags when there is none) and the sentence to show.
void analyse(const WorkspaceSnapshot& snapshot, const ModelEntry& entry, RangeKind kind, int maxLag,
             ResidualAnalysis& analysis, QString& text, double& sampleTime) {
  if (!snapshot.data || !snapshot.data->input() || !snapshot.data->output()) {
    text = QObject::tr("Open a log with an input and an output channel first.");
    return;
  }
  ResidualsRequest request;
  request.data = evaluationDataOf(snapshot);
  request.model = entry.evaluated();
  request.range = kind == RangeKind::Validation ? DataRange::Validation : DataRange::Estimation;
  request.options.maxLag = maxLag;
  ResidualsResult r;
  try {
    r = runResiduals(request);
  } catch (const std::invalid_argument& e) {
    text = QString::fromStdString(e.what());
    return;
  }
  text = QString::fromStdString(r.summary());
  if (!r.ok()) return;
  analysis = r.analysis;
  sampleTime = r.sampleTime;
}

}  // namespace

void ResidualsPanel::refresh() {
  if (filling_) return;
  const int index = model_->currentIndex();
  const auto& list = workspace_->models();
  if (index < 0 || index >= static_cast<int>(list.size())) {
    worker_->cancel();
    analysis_ = ResidualAnalysis{};
    for (QCustomPlot* p : {auto_, cross_}) {
      p->clearPlottables();
      p->clearItems();
      p->replot();
    }
    verdict_->setText(tr("No model in the list yet."));
    return;
  }
  verdict_->setText(tr("Computing the residuals..."));
  const auto kind = static_cast<RangeKind>(range_->currentData().toInt());
  worker_->run([this, snapshot = snapshotOf(*workspace_), entry = list[static_cast<std::size_t>(index)],
                kind, maxLag = lags_->value()](const std::atomic<bool>&) -> BackgroundRefresh::Apply {
    auto analysis = std::make_shared<ResidualAnalysis>();
    auto text = std::make_shared<QString>();
    auto sampleTime = std::make_shared<double>(0.0);
    analyse(snapshot, entry, kind, maxLag, *analysis, *text, *sampleTime);
    return [this, analysis, text, sampleTime, maxLag] {
      analysis_ = *analysis;
      for (QCustomPlot* p : {auto_, cross_}) {
        p->clearPlottables();
        p->clearItems();
        p->replot();
      }
      verdict_->setText(*text);
      if (analysis_.lags.empty()) return;
      // Lags count samples of the data the model works at; the label gives their length.
      const QString lagLabel = tr("lag [samples of %1 ms]").arg(*sampleTime * 1000.0, 0, 'g', 4);
      for (QCustomPlot* p : {auto_, cross_}) p->xAxis->setLabel(lagLabel);
      showCorrelation(auto_, analysis_.lags, analysis_.autocorrelation, analysis_.autocorrelationBound, 1);
      showCorrelation(cross_, analysis_.crossLags, analysis_.crossCorrelation,
                      analysis_.crossCorrelationBound, -maxLag);
    };
  });
}

}  // namespace flexarm
