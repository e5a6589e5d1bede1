#include "widgets/bode_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFileDialog>
#include <QHBoxLayout>
#include <QLabel>
#include <QListWidget>
#include <QPushButton>
#include <QSpinBox>
#include <QSplitter>
#include <QStackedWidget>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>

#include "core/ident/nonparametric.h"
#include "core/ident/transient.h"
#include "core/models/analysis.h"
#include "widgets/background_refresh.h"
#include "widgets/ident_data.h"
#include "widgets/plots/bode_plot.h"
#include "widgets/plots/transient_plot.h"

namespace flexarm {
namespace {

// A percentage without trailing zeros: "99 %", "99.5 %".
class PercentSpinBox : public QDoubleSpinBox {
 public:
  using QDoubleSpinBox::QDoubleSpinBox;
  QString textFromValue(double v) const override { return QString::number(v, 'g', 4); }
};

const QColor kPalette[] = {QColor(31, 119, 180), QColor(214, 39, 40), QColor(44, 160, 44),
                           QColor(148, 103, 189), QColor(255, 127, 14), QColor(23, 190, 207),
                           QColor(140, 86, 75), QColor(227, 119, 194)};

BodeCurve toCurve(const QString& name, const QColor& color, const FrequencyResponse& fr) {
  BodeCurve c;
  c.name = name;
  c.color = color;
  c.frequency = fr.omega;
  c.response = fr.value;
  if (fr.hasBands()) {
    c.magnitudeLow = fr.magnitudeLower;
    c.magnitudeHigh = fr.magnitudeUpper;
    for (std::size_t i = 0; i < fr.omega.size(); ++i) {
      // Bands around the wrapped phase of the value, as BodePlot expects.
      const double offset = std::arg(fr.value[i]) - fr.phase[i];
      c.phaseLowDeg.push_back((fr.phaseLower[i] + offset) * 180.0 / M_PI);
      c.phaseHighDeg.push_back((fr.phaseUpper[i] + offset) * 180.0 / M_PI);
    }
  }
  return c;
}

}  // namespace

BodePanel::BodePanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), models_(new QListWidget(this)),
      level_(new PercentSpinBox(this)), spa_(new QCheckBox(tr("SPA"), this)),
      etfe_(new QCheckBox(tr("ETFE"), this)), window_(new QSpinBox(this)),
      export_(new QPushButton(tr("Export..."), this)), view_(new QComboBox(this)),
      stack_(new QStackedWidget(this)), plot_(new BodePlot(this)), transient_(new TransientPlot(this)),
      note_(new QLabel(this)), worker_(new BackgroundRefresh(this)) {
  setObjectName("bodePanel");
  models_->setObjectName("bodeModelList");
  models_->setMaximumWidth(220);
  models_->setToolTip(tr("Checked models of the shared list are drawn"));
  level_->setObjectName("bodeLevelSpin");
  // Shown in percent ("99 %"); the analysis takes the fraction.
  level_->setRange(50.0, 99.99);
  level_->setDecimals(2);
  level_->setSingleStep(1.0);
  level_->setSuffix(" %");
  level_->setValue(99.0);
  level_->setToolTip(tr("Confidence level of the shaded bands"));
  spa_->setObjectName("bodeSpaCheck");
  spa_->setToolTip(tr("Spectral analysis (4.28) of the estimation data"));
  etfe_->setObjectName("bodeEtfeCheck");
  etfe_->setToolTip(tr("Empirical transfer function estimate (4.24), smoothed (4.25)"));
  window_->setObjectName("bodeWindowSpin");
  window_->setRange(0, 20000);
  window_->setValue(400);
  window_->setToolTip(tr("SPA lag window width M in samples (0: chosen from the data, 1 s of lags and at most "
                         "N/10, SITB's min(N/10, 30) for slow data; the result says which); ETFE uses "
                         "M/50 bins of smoothing"));
  export_->setObjectName("bodeExportButton");
  export_->setToolTip(tr("Save the Bode plot as PNG, PDF or SVG"));
  note_->setObjectName("bodeNote");
  note_->setWordWrap(true);
  note_->setMinimumHeight(4 * note_->fontMetrics().lineSpacing());
  note_->setAlignment(Qt::AlignLeft | Qt::AlignTop);

  view_->setObjectName("bodeViewCombo");
  view_->addItem(tr("Bode"));
  view_->addItem(tr("Step"));
  view_->addItem(tr("Impulse"));
  view_->setToolTip(tr("The frequency response, or the step or impulse response of each model from rest (the "
                       "impulse a pulse of area 1), each with its band from the model's covariance"));
  stack_->addWidget(plot_);
  stack_->addWidget(transient_);
  auto* controls = new QHBoxLayout;
  controls->addWidget(view_);
  controls->addWidget(new QLabel(tr("Band level"), this));
  controls->addWidget(level_);
  controls->addWidget(spa_);
  controls->addWidget(etfe_);
  controls->addWidget(new QLabel(tr("Window"), this));
  controls->addWidget(window_);
  controls->addStretch(1);
  controls->addWidget(export_);
  auto* split = new QSplitter(Qt::Horizontal, this);
  split->addWidget(models_);
  split->addWidget(stack_);
  split->setStretchFactor(1, 4);
  auto* layout = new QVBoxLayout(this);
  layout->addLayout(controls);
  layout->addWidget(split, 1);
  layout->addWidget(note_);

  connect(models_, &QListWidget::itemChanged, this, &BodePanel::refresh);
  connect(level_, QOverload<double>::of(&QDoubleSpinBox::valueChanged), this, &BodePanel::refresh);
  connect(window_, QOverload<int>::of(&QSpinBox::valueChanged), this, &BodePanel::refresh);
  connect(view_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this](int v) {
    stack_->setCurrentIndex(v == 0 ? 0 : 1);
    for (QWidget* w : {static_cast<QWidget*>(spa_), static_cast<QWidget*>(etfe_), static_cast<QWidget*>(window_)})
      w->setEnabled(v == 0);
    refresh();
  });
  for (QCheckBox* c : {spa_, etfe_}) connect(c, &QCheckBox::toggled, this, &BodePanel::refresh);
  connect(export_, &QPushButton::clicked, this, &BodePanel::exportDialog);
  connect(workspace_, &Workspace::modelsChanged, this, [this](int) { refillList(); });
  // Another log (or its preprocessing) changes which models are of the open data.
  connect(workspace_, &Workspace::currentChanged, this, &BodePanel::refillList);
  connect(workspace_, &Workspace::rangesChanged, this, &BodePanel::refresh);
  refillList();
}

void BodePanel::refillList() {
  fillModelChecklist(models_, workspace_->models(), *workspace_);
  refresh();
}

void BodePanel::setModelShown(int index, bool shown) {
  if (index < 0 || index >= models_->count()) return;
  models_->item(index)->setCheckState(shown ? Qt::Checked : Qt::Unchecked);
}

void BodePanel::setLevel(double level) { level_->setValue(100.0 * level); }

void BodePanel::setNonparametricShown(bool spa, bool etfe) {
  filling_ = true;
  spa_->setChecked(spa);
  filling_ = false;
  etfe_->setChecked(etfe);
  refresh();
}

void BodePanel::setView(int view) { view_->setCurrentIndex(std::clamp(view, 0, 2)); }

int BodePanel::view() const { return view_->currentIndex(); }

bool BodePanel::curveHasBand(int curve) const {
  return curve >= 0 && curve < static_cast<int>(bands_.size()) && bands_[static_cast<std::size_t>(curve)];
}

QString BodePanel::noteText() const { return note_->text(); }

bool BodePanel::isBusy() const { return worker_->isBusy(); }

namespace {

struct BodeChoices {
  int view = 0;  // 0 Bode, 1 step, 2 impulse
  std::vector<bool> checked;
  double level = 0.99;
  int window = 100;
  bool spa = false, etfe = false;
};

// The curves of the checked models and the nonparametric estimates with the notes to show:
// the work that grows with the log (SPA and ETFE on the estimation data).
void bodeCurves(const WorkspaceSnapshot& snapshot, const std::vector<ModelEntry>& list,
                const BodeChoices& c, std::vector<BodeCurve>& curves, QStringList& notes) {
  QString why;
  const bool nonparametric = c.spa || c.etfe;
  const auto data = workspaceData(snapshot, 1, true, &why);
  double wmin = 1.0, wmax = 2000.0;
  if (data) {
    wmin = std::max(2.0 * M_PI / (static_cast<double>(data->estimation.size()) * data->sampleTime), 0.5);
    wmax = M_PI / data->sampleTime;
  }
  const auto grid = logGrid(wmin, wmax, 800);
  int colour = 0;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const QColor color = kPalette[colour++ % 8];
    if (!c.checked[i]) continue;
    try {
      const FrequencyResponse fr = responseOf(list[i], grid, c.level);
      if (fr.omega.empty()) continue;
      BodeCurve curve = toCurve(nameOf(list[i]), color, fr);
      // A click reads the model's own notches and peaks, the numbers the Model panel prints
      // (notchesAndPeaks on the exact response), not the nearest grid point.
      auto magnitudeAt = [&](double w) {
        const FrequencyResponse at = responseOf(list[i], {w}, c.level);
        return at.value.empty() ? 0.0 : std::abs(at.value.front());
      };
      if (const auto sys = analysedStateSpace(list[i])) {
        curve.extrema = curveExtrema(notchesAndPeaks(*sys), magnitudeAt);
        curve.extremaKnown = true;
      } else if (fr.omega.size() >= 3) {  // black box: its own response, refined exactly
        std::vector<double> magnitude;
        for (const auto& h : fr.value) magnitude.push_back(std::abs(h));
        curve.extrema = curveExtrema(magnitudeExtrema(fr.omega, magnitude, 1.0, magnitudeAt), magnitudeAt);
        curve.extremaKnown = true;
      }
      curves.push_back(std::move(curve));
    } catch (const std::exception& e) {
      notes << QObject::tr("%1: %2").arg(nameOf(list[i]), QString::fromStdString(e.what()));
    }
  }
  if (nonparametric && !data) notes << why;
  if (data && nonparametric) {
    const auto b = static_cast<Eigen::Index>(data->estimation.begin);
    const auto n = static_cast<Eigen::Index>(data->estimation.size());
    const Eigen::VectorXd u = data->u.segment(b, n), y = data->y.segment(b, n);
    const auto pointsGrid = logGrid(wmin, wmax, 250);
    auto addPoints = [&](const QString& name, const QColor& color, const NonparametricEstimate& e) {
      if (e.termination != Termination::Converged) {
        notes << QObject::tr("%1: %2").arg(name, QString::fromStdString(e.message));
        return;
      }
      if (e.omittedFrequencies > 0) notes << QObject::tr("%1: %2").arg(name, QString::fromStdString(e.message));
      BodeCurve curve = toCurve(name, color, e.response);
      curve.points = true;
      curve.magnitudeLow.clear();  // points only: the SPA region is drawn for models
      curve.magnitudeHigh.clear();
      curve.phaseLowDeg.clear();
      curve.phaseHighDeg.clear();
      curves.push_back(std::move(curve));
    };
    if (c.spa) {
      SpaOptions so;
      so.windowWidth = c.window;
      so.omega = pointsGrid;
      so.level = c.level;
      addPoints(QObject::tr("SPA (M = %1)").arg(c.window), QColor(90, 90, 90), spa(u, y, data->sampleTime, so));
    }
    if (c.etfe) {
      EtfeOptions eo;
      eo.smoothingWidth = std::max(1, c.window / 50);
      eo.omega = pointsGrid;
      addPoints(QObject::tr("ETFE"), QColor(180, 140, 20), etfe(u, y, data->sampleTime, eo));
    }
    if (data->closedLoop) notes << QString::fromUtf8(kClosedLoopBiasWarning);
  }
  if (curves.empty())
    notes.prepend(QObject::tr("No curve: add a model (Model or Fit panel) or tick SPA/ETFE with a log open."));
  else
    notes.prepend(QObject::tr("Bands: %1 % confidence (Gauss approximation).").arg(100.0 * c.level, 0, 'g', 4));
}

struct TransientCurve {
  QString name;
  QColor color;
  TransientResponse response;
};

// The step or impulse responses of the checked models, a physical one sampled at its fit's
// rate on the open log (1 ms without one), a black-box one at its own.
void transientCurves(const WorkspaceSnapshot& snapshot, const std::vector<ModelEntry>& list, const BodeChoices& c,
                     std::vector<TransientCurve>& curves, QStringList& notes) {
  QString why;
  const auto data = workspaceData(snapshot, 1, false, &why);
  const TransientKind kind = c.view == 1 ? TransientKind::Step : TransientKind::Impulse;
  int colour = 0;
  for (std::size_t i = 0; i < list.size(); ++i) {
    const QColor color = kPalette[colour++ % 8];
    if (!c.checked[i]) continue;
    const ModelEntry& e = list[i];
    const double T = data ? data->sampleTime * e.decimation() : 1e-3;
    try {
      curves.push_back({nameOf(e), color,
                        transientResponse(e.model.get(), e.covariance, e.covarianceIndices, e.polynomial.get(), kind, T,
                                          c.level)});
    } catch (const std::exception& ex) {
      notes << QObject::tr("%1: %2").arg(nameOf(e), QString::fromStdString(ex.what()));
    }
  }
  if (curves.empty())
    notes.prepend(QObject::tr("No curve: add a model (Model or Fit panel) and tick it."));
  else
    notes.prepend(QObject::tr("%1 responses from rest%2; bands: %3 % confidence, the estimate's covariance carried "
                              "to the response (Gauss approximation); a model without a covariance has none.")
                      .arg(kind == TransientKind::Step ? QObject::tr("Step") : QObject::tr("Impulse"),
                           kind == TransientKind::Impulse ? QObject::tr(" (a pulse of area 1)") : QString())
                      .arg(100.0 * c.level, 0, 'g', 4));
}

}  // namespace

void BodePanel::refresh() {
  if (filling_) return;
  BodeChoices c;
  for (std::size_t i = 0; i < workspace_->models().size(); ++i) c.checked.push_back(isModelChecked(models_, i));
  c.level = level_->value() / 100.0;  // the spin box shows percent
  c.window = window_->value();
  c.spa = spa_->isChecked();
  c.etfe = etfe_->isChecked();
  c.view = view_->currentIndex();
  if (c.view != 0) {
    worker_->run([this, snapshot = snapshotOf(*workspace_), list = workspace_->models(),
                  c](const std::atomic<bool>&) -> BackgroundRefresh::Apply {
      auto curves = std::make_shared<std::vector<TransientCurve>>();
      auto notes = std::make_shared<QStringList>();
      transientCurves(snapshot, list, c, *curves, *notes);
      return [this, curves, notes, kind = c.view == 1 ? TransientKind::Step : TransientKind::Impulse] {
        transient_->clear();
        transient_->setKind(kind);
        names_.clear();
        bands_.clear();
        for (const auto& t : *curves) {
          transient_->addCurve(t.name, t.color, t.response);
          names_ << t.name;
          bands_.push_back(t.response.hasBand());
        }
        note_->setText(notes->join("\n"));
        transient_->rescale();
      };
    });
    return;
  }
  worker_->run([this, snapshot = snapshotOf(*workspace_), list = workspace_->models(),
                c](const std::atomic<bool>&) -> BackgroundRefresh::Apply {
    auto curves = std::make_shared<std::vector<BodeCurve>>();
    auto notes = std::make_shared<QStringList>();
    bodeCurves(snapshot, list, c, *curves, *notes);
    return [this, curves, notes] {
      plot_->clear();
      names_.clear();
      bands_.clear();
      for (const BodeCurve& curve : *curves) {
        plot_->addCurve(curve);
        names_ << curve.name;
        bands_.push_back(!curve.magnitudeLow.empty());
      }
      note_->setText(notes->join("\n"));
      plot_->rescale();
    };
  });
}

bool BodePanel::exportTo(const QString& path, QString* why) const {
  return view_->currentIndex() == 0 ? plot_->exportTo(path, why) : transient_->exportTo(path, why);
}

void BodePanel::exportDialog() {
  const QString path = QFileDialog::getSaveFileName(this, tr("Export Bode plot"), "bode.png",
                                                    tr("Images (*.png *.pdf *.svg)"));
  if (path.isEmpty()) return;
  QString why;
  if (!exportTo(path, &why)) note_->setText(tr("Export failed: %1").arg(why));
}

}  // namespace flexarm
