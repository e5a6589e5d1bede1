#include "widgets/fit_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QFileDialog>
#include <QFormLayout>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QListWidget>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QLineEdit>
#include <QTableWidget>
#include <QEvent>
#include <QTimer>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <algorithm>
#include <cmath>

#include "core/ident/blackbox.h"
#include "core/ident/fit_spec.h"
#include "core/ident/fit_text.h"
#include "core/ident/nonparametric.h"
#include "core/models/physical_models.h"
#include "core/session/fit_report.h"
#include "core/session/fit_request.h"
#include "widgets/ident_data.h"

namespace flexarm {
namespace {

QString joined(const std::vector<double>& w) { return QString::fromStdString(frequencyList(w)); }

QString number(double v) { return QString::number(v, 'g', 5); }

QString labelOf(const std::string& name, EffectKind kind) {
  return QString::fromStdString(fitParameterLabel(name, toString(kind)));
}

}  // namespace

FitPanel::FitPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), model_(new QComboBox(this)),
      na_(new QSpinBox(this)), nb_(new QSpinBox(this)), nc_(new QSpinBox(this)),
      nd_(new QSpinBox(this)), nf_(new QSpinBox(this)), nk_(new QSpinBox(this)),
      free_(new QListWidget(this)), startsBounds_(new QLineEdit(this)), more_(new QLineEdit(this)), moreBrowse_(new QPushButton(QStringLiteral("..."), this)), ranges_(new QLabel(this)), decimation_(new QSpinBox(this)),
      noise_(new QComboBox(this)), closedLoop_(new QComboBox(this)), starts_(new QSpinBox(this)), iterations_(new QSpinBox(this)),
      estimate_(new QPushButton(tr("Estimate"), this)),
      cancel_(new QPushButton(tr("Cancel"), this)), progress_(new QProgressBar(this)),
      table_(new QTableWidget(0, 6, this)), summary_(new QLabel(this)),
      studyRuns_(new QSpinBox(this)), study_button_(new QPushButton(tr("Run study"), this)),
      studyTable_(new QTableWidget(0, 3, this)), studySummary_(new QLabel(this)),
      poll_(new QTimer(this)), permille_(std::make_shared<std::atomic<int>>(0)),
      abort_(std::make_shared<std::atomic<bool>>(false)) {
  setObjectName("fitPanel");
  model_->setObjectName("fitModelCombo");
  model_->setToolTip(tr("What to fit: a black box (4.8: ARX, ARMAX, OE, Box-Jenkins), a state-space "
                        "model by subspace identification refined by prediction error (its order is na; "
                        "0 lets the data choose it by MDL), a physical model of the shared list from its "
                        "values, or a structure (5.1, 5.3) from its nominal values"));
  const int defaults[] = {2, 4, 2, 2, 4, 1};
  auto* orderRow = new QGridLayout;  // two rows of three: the panel stays narrow
  orderRow->setContentsMargins(0, 0, 0, 0);
  int i = 0;
  for (const auto& [order, spin] : orderSpins()) {
    const QString name = toString(order);
    spin->setRange(0, 60);
    spin->setValue(defaults[i]);
    spin->setObjectName(QString("%1Spin").arg(name));
    spin->setToolTip(tr("Order %1 of (4.8)").arg(name));
    orderRow->addWidget(new QLabel(name, this), i / 3, 2 * (i % 3));
    orderRow->addWidget(spin, i / 3, 2 * (i % 3) + 1);
    ++i;
  }
  // The named effects a physical model can carry in the fit (extra_mass is a larger
  // structure, chosen as the model).
  effectsBox_ = new QWidget(this);
  effectsBox_->setObjectName("fitEffectsBox");
  auto* effectGrid = new QGridLayout(effectsBox_);
  effectGrid->setContentsMargins(0, 0, 0, 0);
  for (EffectKind k : allEffectKinds()) {
    if (k == EffectKind::ExtraMass) continue;
    auto* box = new QCheckBox(QString::fromStdString(toString(k)), effectsBox_);
    box->setObjectName(QString("effect_%1_check").arg(toString(k)));
    QStringList meaning;
    for (const auto& p : effectParameters(k))
      meaning << tr("%1 (%2): %3").arg(QString::fromStdString(p.name), QString::fromStdString(p.unit),
                                       QString::fromStdString(p.meaning));
    box->setToolTip(tr("Fit the model with this effect (nonlinear grey-box estimation, the plant "
                       "simulated from the measured torque): ") + meaning.join("; "));
    const int n = static_cast<int>(effectChecks_.size());
    effectGrid->addWidget(box, n / 2, n % 2);
    effectChecks_.emplace_back(k, box);
    connect(box, &QCheckBox::toggled, this, [this] { refillEffectParameters(); });
  }
  free_->setObjectName("freeParameterList");
  free_->setMaximumHeight(90);
  free_->setToolTip(tr("Checked parameters are estimated; the others keep their values"));
  startsBounds_->setObjectName("startsBoundsEdit");
  startsBounds_->setPlaceholderText(tr("e.g. J_m=1e-3, r=1, d_g=-inf:inf"));
  startsBounds_->setToolTip(tr("Start values P=V (else the model's; r=1 refers the parameters behind "
                               "the gear to the motor side) and bounds P=LO:HI, comma-separated. "
                               "Dampings d_* are non-negative unless bounded otherwise; a parameter "
                               "that ends on a bound is named in the notes"));
  more_->setObjectName("fitMoreExperimentsEdit");
  more_->setPlaceholderText(tr("e.g. b.csv@0:10, val: c.csv"));
  more_->setToolTip(tr("More experiments besides the open log's ranges, comma-separated: FILE or "
                       "FILE@A:B (seconds) for estimation, val: FILE[@A:B] for validation. Without "
                       "a range, the range stored in the log, else all of it. The loss sums over "
                       "every estimation experiment, each simulated from its own first sample; "
                       "each experiment's fit % is listed (flexarm fit --log / --validation-log)"));
  moreBrowse_->setObjectName("fitMoreExperimentsBrowse");
  moreBrowse_->setToolTip(tr("Add log files as estimation experiments"));
  connect(moreBrowse_, &QPushButton::clicked, this, &FitPanel::chooseExperimentFiles);
  ranges_->setObjectName("fitRangesLabel");
  ranges_->setWordWrap(true);
  decimation_->setRange(1, 100);
  decimation_->setObjectName("fitDecimationSpin");
  decimation_->setToolTip(tr("Decimate behind the anti-alias FIR before fitting (the seed: "
                             "10); 1 fits at the data's own rate, where the zero-order hold "
                             "the physical models assume is what the controller does"));
  noise_->setObjectName("noiseModelCombo");
  noise_->addItem(tr("Output error (K = 0)"), "output-error");
  noise_->addItem(tr("Innovations form (K estimated)"), "innovations");
  noise_->addItem(tr("Output error of the motor and the arm encoder"), "motor-and-arm");
  noise_->setToolTip(tr("Output error: the model's simulation against the log (K = 0); "
                        "innovations form: a Kalman gain K is estimated too and the one-step "
                        "prediction error (4.5) is minimised (4.6); motor and arm encoder (a log "
                        "with arm_angle_rad): the deflection r phi_m - phi_a is fitted as a second "
                        "output, each weighted by its noise (flexarm fit --outputs motor,arm)"));
  closedLoop_->setObjectName("closedLoopCombo");
  closedLoop_->addItem(tr("Auto: indirect when the controller is known or identified"), "auto");
  closedLoop_->addItem(tr("Two-stage: fit to the input part the reference explains"), "two-stage");
  closedLoop_->addItem(tr("Direct: fit to the logged input"), "direct");
  closedLoop_->addItem(tr("Indirect: the log's controller closed around the model"), "indirect");
  closedLoop_->setToolTip(tr("For output-error fits of logs with a reference channel. Noise "
                             "reaches the input through the controller, which biases the "
                             "direct fit (4.43); the two-stage fit is consistent and its "
                             "intervals allow coloured errors; the indirect fit closes the "
                             "log's controller (from its metadata, else the cascade of Figure "
                             "5.1 identified from the log) around the model and fits the loop "
                             "from the reference (undecimated logs). Auto takes the indirect "
                             "fit whenever it can: on simulated logs it was unbiased with honest "
                             "99 % intervals at every noise level"));
  starts_->setRange(0, 200);
  starts_->setObjectName("startsSpin");
  starts_->setToolTip(tr("Random starts besides the model's own values, plus two whose "
                         "notches and peaks match the SPA estimate"));
  iterations_->setRange(1, 1000);
  iterations_->setValue(100);
  iterations_->setToolTip(tr("Most Gauss-Newton iterations of the prediction-error criterion (4.6)"));

  // Two columns, the model on the left and the data and estimator on the right: the panel
  // holds its Estimate button and results on a laptop screen without scrolling.
  for (QComboBox* c : {model_, noise_, closedLoop_}) {
    c->setSizeAdjustPolicy(QComboBox::AdjustToMinimumContentsLengthWithIcon);
    c->setMinimumContentsLength(14);
  }
  auto* form = new QFormLayout;
  form->addRow(tr("Model"), model_);
  form->addRow(tr("Orders"), orderRow);
  form->addRow(tr("Effects"), effectsBox_);
  form->addRow(tr("Free parameters"), free_);
  form->addRow(tr("Starts, bounds"), startsBounds_);
  auto* data = new QFormLayout;
  data->addRow(tr("Ranges"), ranges_);
  auto* moreRow = new QHBoxLayout;
  moreRow->setContentsMargins(0, 0, 0, 0);
  moreRow->addWidget(more_, 1);
  moreRow->addWidget(moreBrowse_);
  data->addRow(tr("More experiments"), moreRow);
  data->addRow(tr("Decimation"), decimation_);
  data->addRow(tr("Noise model"), noise_);
  data->addRow(tr("Closed loop"), closedLoop_);
  data->addRow(tr("Extra starts"), starts_);
  data->addRow(tr("Max iterations"), iterations_);
  auto* forms = new QHBoxLayout;
  forms->addLayout(form, 1);
  forms->addLayout(data, 1);

  estimate_->setObjectName("estimateButton");
  cancel_->setObjectName("fitCancelButton");
  estimate_->setToolTip(tr("Fit the model to the estimation range by prediction error (4.6), with "
                           "99 % intervals of the free parameters"));
  cancel_->setToolTip(tr("Stop the fit; the model list stays as it was"));
  cancel_->setEnabled(false);
  progress_->setObjectName("fitProgress");
  progress_->setRange(0, 1000);
  progress_->setValue(0);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(estimate_);
  buttons->addWidget(cancel_);
  buttons->addWidget(progress_, 1);

  table_->setObjectName("fitResultsTable");
  table_->setHorizontalHeaderLabels(
      {tr("Parameter"), tr("Value"), tr("Std"), tr("99 % low"), tr("99 % high"), tr("Unit")});
  table_->horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  table_->verticalHeader()->setVisible(false);
  table_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  // The whole summary at once, however long (the method, the controller, why a fit stopped
  // at a bound or the iteration limit): it wraps and grows, and the panel scrolls.
  summary_->setObjectName("fitSummary");
  summary_->setWordWrap(true);
  summary_->setTextFormat(Qt::PlainText);
  summary_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  summary_->setAlignment(Qt::AlignLeft | Qt::AlignTop);
  summary_->installEventFilter(this);  // its height follows its text (eventFilter)

  auto* studyBox = new QGroupBox(tr("Sensitivity study (Section 5.3.3)"), this);
  studyRuns_->setRange(1, 100000);
  studyRuns_->setValue(1000);
  studyRuns_->setObjectName("studyRunsSpin");
  studyRuns_->setToolTip(tr("Number of Monte-Carlo fits from random starts inside the domain of "
                            "attraction (Section 5.3.3)"));
  study_button_->setObjectName("studyButton");
  study_button_->setEnabled(false);
  study_button_->setToolTip(tr("Domain of attraction of every free parameter by interval "
                               "halving (Table 5.8), then Monte-Carlo fits from random starts "
                               "inside it; on the latest physical estimate"));
  studyTable_->setObjectName("studyTable");
  studyTable_->setHorizontalHeaderLabels({tr("Parameter"), tr("Lower limit"), tr("Upper limit")});
  studyTable_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  studyTable_->verticalHeader()->setVisible(false);
  studyTable_->setEditTriggers(QAbstractItemView::NoEditTriggers);
  studyTable_->setMaximumHeight(90);
  studySummary_->setObjectName("studySummary");
  studySummary_->setWordWrap(true);
  auto* studyRow = new QHBoxLayout;
  studyRow->addWidget(new QLabel(tr("Monte-Carlo runs"), this));
  studyRow->addWidget(studyRuns_);
  studyRow->addWidget(study_button_);
  studyRow->addStretch(1);
  auto* studyLayout = new QVBoxLayout(studyBox);
  studyLayout->addLayout(studyRow);
  studyLayout->addWidget(studyTable_);
  studyLayout->addWidget(studySummary_);

  auto* layout = new QVBoxLayout(this);
  layout->addLayout(forms);
  layout->addLayout(buttons);
  layout->addWidget(table_, 3);
  layout->addWidget(summary_);
  layout->addWidget(studyBox);

  poll_->setInterval(100);
  connect(poll_, &QTimer::timeout, this, [this] { progress_->setValue(permille_->load()); });
  connect(model_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, [this] {
    refillParameters();
    updateControls();
  });
  connect(noise_, QOverload<int>::of(&QComboBox::currentIndexChanged), this,
          &FitPanel::updateControls);
  connect(estimate_, &QPushButton::clicked, this, &FitPanel::estimate);
  connect(cancel_, &QPushButton::clicked, this, &FitPanel::cancel);
  connect(study_button_, &QPushButton::clicked, this, &FitPanel::runStudy);
  connect(&watcher_, &QFutureWatcher<Outcome>::finished, this, &FitPanel::onFinished);
  connect(&study_, &QFutureWatcher<StudyOutcome>::finished, this, &FitPanel::onStudyFinished);
  connect(workspace_, &Workspace::modelsChanged, this, [this](int index) {
    if (index < 0) refillModels();
  });
  for (auto signal : {&Workspace::currentChanged, &Workspace::rangesChanged})
    connect(workspace_, signal, this, &FitPanel::showRanges);
  connect(workspace_, &Workspace::resultWithdrawn, this, [this](const QString& key) {
    if (key == "fit") withdraw();
  });
  refillModels();
  showRanges();
}

void FitPanel::refillModels() {
  const QString keep = modelChoice();
  model_->blockSignals(true);
  model_->clear();
  model_->addItem(tr("ARX (least squares)"), "arx");
  model_->addItem(tr("ARMAX"), "armax");
  model_->addItem(tr("OE"), "oe");
  model_->addItem(tr("Box-Jenkins"), "bj");
  model_->addItem(tr("State space (subspace, then PEM; order na, 0: by MDL)"), "ss");
  const auto& list = workspace_->models();
  for (std::size_t i = 0; i < list.size(); ++i)
    if (list[i].model)
      model_->addItem(tr("%1 (model list)").arg(nameOf(list[i])), QString("list:%1").arg(i));
  for (const auto& s : modelStructureNames())
    model_->addItem(tr("%1, nominal values").arg(QString::fromStdString(s)),
                    QString::fromStdString(s));
  const int k = model_->findData(keep);
  model_->setCurrentIndex(k >= 0 ? k : 2);
  model_->blockSignals(false);
  const QStringList ticked = freeParameters();  // the user's choice survives a list change
  const QStringList chosen = effects();
  refillParameters();
  if (k >= 0) setEffects(chosen);
  if (k >= 0 && !ticked.isEmpty()) setFreeParameters(ticked);
  updateControls();
}

bool FitPanel::setModelChoice(const QString& key) {
  const int k = model_->findData(key);
  if (k < 0) return false;
  model_->setCurrentIndex(k);
  return true;
}

QString FitPanel::modelChoice() const { return model_->currentData().toString(); }

void FitPanel::setOrders(const PolyOrders& o) {
  for (const auto& [order, spin] : orderSpins()) spin->setValue(o[order]);
}

std::vector<std::pair<PolyOrder, QSpinBox*>> FitPanel::orderSpins() const {
  return {{PolyOrder::Na, na_}, {PolyOrder::Nb, nb_}, {PolyOrder::Nc, nc_},
          {PolyOrder::Nd, nd_}, {PolyOrder::Nf, nf_}, {PolyOrder::Nk, nk_}};
}

void FitPanel::setFreeParameters(const QStringList& names) {
  for (int i = 0; i < free_->count(); ++i)
    free_->item(i)->setCheckState(names.contains(free_->item(i)->text()) ? Qt::Checked
                                                                       : Qt::Unchecked);
}

QStringList FitPanel::freeParameters() const {
  QStringList names;
  for (int i = 0; i < free_->count(); ++i)
    if (free_->item(i)->checkState() == Qt::Checked) names << free_->item(i)->text();
  return names;
}

void FitPanel::setDecimation(int factor) { decimation_->setValue(factor); }
void FitPanel::setNoiseModel(NoiseModel m) { noise_->setCurrentIndex(m == NoiseModel::Innovations); }
void FitPanel::setClosedLoopMethod(ClosedLoopChoice m) {
  closedLoop_->setCurrentIndex(std::max(0, closedLoop_->findData(QString(toString(m)))));
}
void FitPanel::setStarts(int randomStarts) { starts_->setValue(randomStarts); }
void FitPanel::setStudyRuns(int runs) { studyRuns_->setValue(runs); }

void FitPanel::setEffects(const QStringList& names) {
  for (auto& [kind, box] : effectChecks_) {
    box->blockSignals(true);
    box->setChecked(names.contains(QString::fromStdString(toString(kind))));
    box->blockSignals(false);
  }
  refillEffectParameters();
}

QStringList FitPanel::effects() const {
  QStringList names;
  for (const auto& [kind, box] : effectChecks_)
    if (box->isChecked()) names << QString::fromStdString(toString(kind));
  return names;
}

std::vector<Effect> FitPanel::startEffects() const {
  const QString key = modelChoice();
  if (!key.startsWith("list:")) return {};
  const auto i = key.mid(5).toUInt();
  return i < workspace_->models().size() ? workspace_->models()[i].effects : std::vector<Effect>{};
}

// The effects checked, their values the start model's own where it has them, free as the
// parameter list says.
std::vector<FitEffect> FitPanel::chosenEffects() const {
  std::vector<FitEffect> out;
  const std::vector<Effect> own = startEffects();
  const QStringList ticked = freeParameters();
  for (const auto& [kind, box] : effectChecks_) {
    if (!box->isChecked()) continue;
    FitEffect f = fitEffectFor(kind, own);
    const auto& info = effectParameters(kind);
    for (std::size_t k = 0; k < info.size(); ++k) f.free[k] = ticked.contains(labelOf(info[k].name, kind));
    out.push_back(f);
  }
  return out;
}

// The checked effects' parameters at the end of the free-parameter list (a parameter keeps
// its tick while its effect stays checked).
void FitPanel::refillEffectParameters() {
  const QStringList ticked = freeParameters();
  for (int i = free_->count() - 1; i >= 0; --i)
    if (free_->item(i)->data(Qt::UserRole).toBool()) delete free_->takeItem(i);
  const std::vector<Effect> own = startEffects();
  for (const auto& [kind, box] : effectChecks_) {
    if (!box->isChecked()) continue;
    const FitEffect f = fitEffectFor(kind, own);
    const auto& info = effectParameters(kind);
    for (std::size_t k = 0; k < info.size(); ++k) {
      const QString label = labelOf(info[k].name, kind);
      auto* item = new QListWidgetItem(label, free_);
      item->setData(Qt::UserRole, true);
      item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
      const bool wasListed = std::any_of(ticked.begin(), ticked.end(), [&](const QString& t) { return t == label; });
      item->setCheckState(wasListed || f.free[k] ? Qt::Checked : Qt::Unchecked);
      item->setToolTip(tr("%1 %2, start value: %3")
                           .arg(f.effect.values[k])
                           .arg(QString::fromStdString(info[k].unit), QString::fromStdString(info[k].meaning)));
    }
  }
}

void FitPanel::refillParameters() {
  free_->clear();
  setEffects({});  // the start model's own effects, below
  const QString key = modelChoice();
  std::shared_ptr<const PhysicalModel> m;
  if (key.startsWith("list:")) {
    const auto i = key.mid(5).toUInt();
    if (i < workspace_->models().size()) m = workspace_->models()[i].model;
  } else if (!polyStructureFromString(key.toStdString())) {
    m = makeModel(key.toStdString());
  }
  if (!m) return;
  for (const auto& p : m->parameters()) {
    auto* item = new QListWidgetItem(QString::fromStdString(p.name), free_);
    item->setFlags(Qt::ItemIsEnabled | Qt::ItemIsUserCheckable);
    item->setCheckState(p.free ? Qt::Checked : Qt::Unchecked);
    item->setToolTip(tr("%1 %2, start value").arg(p.value).arg(QString::fromStdString(p.unit)));
  }
  QStringList own;
  for (const auto& e : startEffects())
    if (e.kind != EffectKind::ExtraMass) own << QString::fromStdString(toString(e.kind));
  setEffects(own);
}

void FitPanel::updateControls() {
  const auto s = polyStructureFromString(modelChoice().toStdString());
  const bool busy = isBusy();
  for (const auto& [order, spin] : orderSpins()) spin->setEnabled(s && takesOrder(*s, order) && !busy);
  free_->setEnabled(!s && !busy);
  startsBounds_->setEnabled(!s && !busy);
  more_->setEnabled(!busy);
  moreBrowse_->setEnabled(!busy);
  effectsBox_->setEnabled(!s && !busy);
  noise_->setEnabled(!s && !busy);
  closedLoop_->setEnabled(!s && !busy && noise_->currentIndex() == 0);
  starts_->setEnabled(!s && !busy);
  estimate_->setEnabled(!busy && workspace_->current());  // none while a log awaits resampling
  cancel_->setEnabled(busy);
  study_button_->setEnabled(!busy && last_.estimate != nullptr);
  model_->setEnabled(!busy);
}

void FitPanel::showRanges() {
  auto text = [this](RangeKind k) {
    const auto r = workspace_->range(k);
    if (!r) return k == RangeKind::Estimation ? tr("estimation: all data") : tr("validation: none");
    return tr("%1: %2-%3 s (%4 samples)")
        .arg(toString(k))
        .arg(r->start, 0, 'f', 2)
        .arg(r->end, 0, 'f', 2)
        .arg(workspace_->samples(k).size());
  };
  ranges_->setText(text(RangeKind::Estimation) + "; " + text(RangeKind::Validation));
  updateControls();
}

ProgressCallback FitPanel::progressCallback() const {
  auto permille = permille_;
  auto abort = abort_;
  return [permille, abort](double fraction, const std::string&) {
    permille->store(static_cast<int>(1000.0 * std::clamp(fraction, 0.0, 1.0)));
    return abort->load() ? ProgressAction::Abort : ProgressAction::Continue;
  };
}

void FitPanel::startProgress() {
  permille_->store(0);
  abort_->store(false);
  progress_->setValue(0);
  poll_->start();
  updateControls();
}

void FitPanel::cancel() {
  abort_->store(true);
  setSummary(tr("Cancelling..."));
}

// The pipeline's options from the panel's choices and the workspace's data and ranges;
// nullopt after showing why in the summary.
std::optional<FitOptions> FitPanel::options(QString* name, std::vector<ExperimentSource>* more) {
  FitOptions o;
  const QString key = modelChoice();
  o.maxIterations = iterations_->value();
  o.decimation = decimation_->value();
  if (auto s = polyStructureFromString(key.toStdString())) {
    o.model.kind = FitModelKind::BlackBox;
    o.model.structure = *s;
    for (const auto& [order, spin] : orderSpins()) o.model.orders[order] = spin->value();
    o.model.orders = o.model.orders.of(*s);
  } else {
    std::shared_ptr<const PhysicalModel> base;
    if (key.startsWith("list:")) {
      const auto i = key.mid(5).toUInt();
      if (i < workspace_->models().size()) {
        base = workspace_->models()[i].model;
        *name = nameOf(workspace_->models()[i]);
      }
    } else {
      base = makeModel(key.toStdString());
      *name = key;
    }
    if (!base) return std::nullopt;
    o.model.kind = FitModelKind::Physical;
    o.model.start = base;
    o.model.effects = chosenEffects();
    std::vector<std::string> names;
    for (const auto& n : freeParameters()) names.push_back(n.toStdString());
    if (std::string bad; !flexarm::setFreeParameters(o.model, names, &bad)) {
      setSummary(tr("The fit cannot run: %1").arg(QString::fromStdString(bad)));
      return std::nullopt;
    }
    o.noiseModel = noise_->currentIndex() == 1 ? NoiseModel::Innovations : NoiseModel::OutputError;
    o.closedLoop = closedLoopChoiceFromString(closedLoop_->currentData().toString().toStdString())
                       .value_or(ClosedLoopChoice::Auto);
    o.model.armOutput = noise_->currentIndex() == 2;
    if (o.model.armOutput) o.closedLoop = ClosedLoopChoice::Auto;  // the nonlinear fit is direct
    o.randomStarts = starts_->value();
    std::string bad;
    if (!startsAndBoundsFromText(startsBounds_->text().toStdString(), o.startValues, o.bounds, &bad)) {
      setSummary(tr("Starts and bounds: %1.").arg(QString::fromStdString(bad)));
      return std::nullopt;
    }
  }
  if (!workspace_->current()) {
    setSummary(tr("Open a log with an input and an output channel first."));
    return std::nullopt;
  }
  useWorkspaceData(*workspace_, o);
  std::string why;
  if (!o.isValid(&why)) {
    setSummary(tr("The fit cannot run: %1").arg(QString::fromStdString(why)));
    return std::nullopt;
  }
  auto list = experimentListFromText(more_->text().toStdString(), &why);
  if (!list) {
    setSummary(tr("More experiments: %1.").arg(QString::fromStdString(why)));
    return std::nullopt;
  }
  *more = *list;
  return o;
}

void FitPanel::estimate() {
  if (isBusy()) return;
  QString name;
  std::vector<ExperimentSource> more;
  auto o = options(&name, &more);
  if (!o) {
    emit estimated(false);
    return;
  }
  start(*o, name, more);
}

bool FitPanel::recompute(const FitRequest& request) {
  if (isBusy()) return false;
  FitOptions o = request.options;
  useWorkspaceData(*workspace_, o);
  std::string why;
  if (!o.isValid(&why)) {
    setSummary(tr("%1 cannot be recomputed on the open data: %2")
                               .arg(QString::fromStdString(request.name), QString::fromStdString(why)));
    return false;
  }
  const QString name = QString::fromStdString(request.physical() ? o.model.start->structureName() : request.name);
  start(o, name, request.experiments);
  return true;
}

void FitPanel::setMoreExperiments(const QString& text) { more_->setText(text); }
QString FitPanel::moreExperiments() const { return more_->text(); }

void FitPanel::chooseExperimentFiles() {
  const QStringList files = QFileDialog::getOpenFileNames(this, tr("More estimation experiments"), QString(),
                                                          tr("Logs (*.csv *.dat *.txt *.mat);;All files (*)"));
  if (files.isEmpty()) return;
  QStringList items;
  if (!more_->text().trimmed().isEmpty()) items << more_->text().trimmed();
  items << files;
  more_->setText(items.join(", "));
}

void FitPanel::start(const FitOptions& o, const QString& name, const std::vector<ExperimentSource>& more) {
  // The request as a session stores it: the same options and ranges, without the data.
  auto record = std::make_shared<FitRequest>(fitRequestOf(o, more));
  // The data it runs on, with the ranges the fit itself uses.
  record->provenance = workspace_->dataProvenance();
  record->provenance->estimation = record->estimation;
  record->provenance->validation = record->validation;
  table_->setRowCount(0);
  workspace_->forgetResult("fit");
  setSummary(tr("Estimating %1...").arg(QString::fromStdString(o.model.name())));
  startProgress();
  const auto progress = progressCallback();
  // The one fit pipeline (core/ident/fit.h), as `flexarm fit` and a session's replay run it.
  watcher_.setFuture(QtConcurrent::run([options = o, more, record, name, progress]() mutable {
    Outcome out;
    out.request = record;
    out.name = name;
    try {
      // The more experiments' logs are read here, off the GUI thread (fit_experiments.h).
      ExperimentLogs logs;
      std::string why;
      if (!appendExperiments(options, more, LogReadOptions{}, logs, &why)) {
        out.error = tr("more experiments: %1").arg(QString::fromStdString(why));
        return out;
      }
      out.result = fitModel(options, progress);
    } catch (const std::exception& e) {
      out.error = QString::fromStdString(e.what());
    }
    return out;
  }));
  updateControls();  // Cancel on, Estimate off while the future runs
}

void FitPanel::onFinished() {
  poll_->stop();
  Outcome out = watcher_.result();
  const FitResult& r = out.result;
  const bool ok = out.error.isEmpty() && r.ok();
  progress_->setValue(ok ? 1000 : 0);
  if (!ok) {
    const QString reason = !out.error.isEmpty() ? out.error : QString::fromStdString(r.message);
    setSummary(r.termination == Termination::Cancelled ? tr("Cancelled: %1").arg(reason)
                                                              : tr("The fit failed: %1").arg(reason));
    updateControls();
    emit estimated(false);
    return;
  }
  fillTable(r.parameters);
  ModelEntry entry;
  if (r.physical) {
    entry.model = r.physical;
    entry.effects = r.effects;
    entry.covariance = r.covariance;
    entry.covarianceIndices = r.freeIndices;
    entry.smoothingSpeed = r.smoothingSpeed;
    entry.name = out.name.toStdString();
    last_ = {r.physical, r.data.estimationInput(), r.data.estimationOutput(), r.data.sampleTime};
  } else {
    entry.polynomial = r.polynomial;
    entry.name = r.polynomial->name();
  }
  QStringList lines;
  for (const auto& line : fitSummaryLines(r, entry.name,
                                          fitLogNamesOf(*out.request, out.request->provenance->log)))
    lines << QString::fromStdString(line);
  // The estimate joins the shared list under a name no other entry has, naming its data:
  // "three-mass estimate 2 (chirp.csv 0.5-12 s)".
  std::vector<std::string> taken;
  for (const auto& m : workspace_->models()) taken.push_back(m.name);
  const QString name = QString::fromStdString(
      uniqueResultName(entry.name + " estimate", *out.request->provenance, taken));
  entry.name = name.toStdString();
  entry.origin = ModelOrigin::Fit;
  out.request->name = name.toStdString();
  out.request->stored = storedFitOf(r);
  entry.fitRequest = out.request;
  lines << tr("Added to the model list as \"%1\".").arg(name);
  setSummary(lines.join("\n"));
  lastIndex_ = workspace_->addModel(entry);
  lastName_ = name;
  // Shown only beside its data: the open data changed while it ran, it stays in the list.
  if (!workspace_->recordResult("fit", *out.request->provenance)) withdraw();
  updateControls();
  emit estimated(true);
}

void FitPanel::fillTable(const std::vector<FitParameter>& parameters) {
  table_->setRowCount(static_cast<int>(parameters.size()));
  for (int i = 0; i < static_cast<int>(parameters.size()); ++i) {
    const FitParameter& row = parameters[static_cast<std::size_t>(i)];
    // An undetermined parameter shows why instead of a std of 0 or nan and an interval.
    const bool shown = row.free && row.determined;
    const QStringList cells = {QString::fromStdString(fitParameterLabel(row)),
                               number(row.value),
                               !row.free ? tr("fixed") : shown ? number(row.std) : tr("undetermined"),
                               shown ? number(row.lower) : QString(),
                               shown ? number(row.upper) : QString(),
                               QString::fromStdString(row.unit)};
    for (int c = 0; c < cells.size(); ++c) {
      auto* item = new QTableWidgetItem(cells[c]);
      if (!row.free) item->setForeground(QColor(130, 130, 130));
      if (row.free && !row.determined) {
        item->setForeground(QColor(180, 60, 0));
        item->setToolTip(tr("Undetermined: %1.").arg(QString::fromStdString(row.undetermined)));
      }
      table_->setItem(i, c, item);
    }
  }
}

void FitPanel::setChoices(const FitRequest& request) {
  const FitOptions& o = request.options;
  iterations_->setValue(o.maxIterations);
  decimation_->setValue(o.decimation);
  more_->setText(QString::fromStdString(experimentListText(request.experiments)));
  if (!request.physical()) {
    setModelChoice(toString(o.model.structure));
    setOrders(o.model.orders);
    return;
  }
  // A physical fit shows its structure with the free parameters, effects and options it
  // was fitted with; its own start values are in the list's tooltips and the starts field.
  if (o.model.start) setModelChoice(QString::fromStdString(o.model.start->structureName()));
  QStringList effects, free;
  for (const FitEffect& f : o.model.effects) effects << QString::fromStdString(toString(f.effect.kind));
  setEffects(effects);
  for (const auto& label : freeParameterLabels(o.model)) free << QString::fromStdString(label);
  setFreeParameters(free);
  setNoiseModel(o.noiseModel);
  setClosedLoopMethod(o.closedLoop);
  setStarts(o.randomStarts);
  startsBounds_->setText(QString::fromStdString(startsAndBoundsText(o.startValues, o.bounds)));
}

void FitPanel::showStored(const FitRequest& request, int modelIndex) {
  if (isBusy()) return;
  setChoices(request);
  lastIndex_ = modelIndex;
  lastName_ = QString::fromStdString(request.name);
  last_ = {};
  studyTable_->setRowCount(0);
  studySummary_->clear();
  progress_->setValue(0);
  QStringList lines;
  lines << tr("%1: restored from the session, computed on %2.")
               .arg(lastName_, request.provenance ? QString::fromStdString(longDescription(*request.provenance))
                                                  : tr("the session's log"));
  if (const auto& s = request.stored) {
    fillTable(s->parameters);
    QString fits = s->fitEstimation ? tr("Fit %1 % (5.2) on the estimation data").arg(*s->fitEstimation, 0, 'f', 1)
                                    : tr("No fit % (the simulated output diverges)");
    if (s->fitValidation) fits += tr(", %1 % (5.2) on the validation data").arg(*s->fitValidation, 0, 'f', 1);
    lines << tr("Loss %1. %2.").arg(number(s->loss), fits);
    lines << tr("Notches: %1. Peaks: %2.").arg(joined(s->notches), joined(s->peaks));
  } else {
    table_->setRowCount(0);
    lines << tr("The session keeps no numbers of this fit: Estimate computes them again.");
  }
  lines << tr("Estimate runs the fit again with these choices; the sensitivity study needs a new estimate.");
  setSummary(lines.join("\n"));
  if (!workspace_->recordResult("fit", request.provenance.value_or(workspace_->dataProvenance()))) withdraw();
  updateControls();
}

void FitPanel::clearResult() {
  lastName_.clear();
  withdraw();
}

void FitPanel::withdraw() {
  workspace_->forgetResult("fit");
  table_->setRowCount(0);
  last_ = {};
  studyTable_->setRowCount(0);
  studySummary_->clear();
  progress_->setValue(0);
  setSummary(lastName_.isEmpty()
                             ? QString()
                             : tr("The last estimate, \"%1\", was computed on other data than the open "
                                  "ones: it stays in the model list under its name. Estimate again to fit "
                                  "these data.").arg(lastName_));
  updateControls();
}

void FitPanel::setSummary(const QString& text) {
  summary_->setText(text);
  fitSummaryHeight();
}

// A scroll area lays the panel out by its minimum height, which knows nothing of wrapped
// text: the summary asks for the height its lines need at its width.
void FitPanel::fitSummaryHeight() {
  const int need = std::max(4 * summary_->fontMetrics().lineSpacing(), summary_->heightForWidth(summary_->width()));
  if (summary_->minimumHeight() != need) summary_->setMinimumHeight(need);
}

bool FitPanel::eventFilter(QObject* watched, QEvent* event) {
  if (watched == summary_ && event->type() == QEvent::Resize) fitSummaryHeight();
  return QWidget::eventFilter(watched, event);
}

QString FitPanel::summaryText() const { return summary_->text(); }
QString FitPanel::studyText() const { return studySummary_->text(); }

void FitPanel::runStudy() {
  if (isBusy() || !last_.estimate) return;
  const auto model = last_.estimate;
  const Eigen::VectorXd u = last_.u, y = last_.y;
  const double T = last_.sampleTime;
  const int runs = studyRuns_->value();
  studyTable_->setRowCount(0);
  studySummary_->setText(tr("Searching the domain of attraction, then %1 Monte-Carlo fits...")
                             .arg(runs));
  startProgress();
  const auto progress = progressCallback();
  study_.setFuture(QtConcurrent::run([model, u, y, T, runs, progress]() {
    StudyOutcome out;
    auto half = [progress](double offset) {
      return [progress, offset](double f, const std::string& stage) {
        return progress(offset + 0.5 * f, stage);
      };
    };
    try {
      out.attraction = domainOfAttraction(*model, u, y, T, AttractionOptions{}, half(0.0));
      if (out.attraction.termination == Termination::Converged) {
        MonteCarloOptions mc;
        mc.runs = runs;
        out.monteCarlo = monteCarloStarts(*model, u, y, T, out.attraction, mc, half(0.5));
      }
    } catch (const std::exception& e) {
      out.error = QString::fromStdString(e.what());
    }
    return out;
  }));
  updateControls();  // Cancel on, Estimate off while the future runs
}

void FitPanel::onStudyFinished() {
  poll_->stop();
  const StudyOutcome out = study_.result();
  updateControls();
  if (!out.error.isEmpty()) {
    studySummary_->setText(tr("The study failed: %1").arg(out.error));
    emit studyFinished(false);
    return;
  }
  const auto& a = out.attraction;
  auto limit = [](double f, bool open) {
    return QString("%1%2 %").arg(open ? "beyond " : "").arg(100.0 * f, 0, 'g', 4);
  };
  studyTable_->setRowCount(static_cast<int>(a.parameters.size()));
  for (int r = 0; r < static_cast<int>(a.parameters.size()); ++r) {
    const auto& p = a.parameters[static_cast<std::size_t>(r)];
    studyTable_->setItem(r, 0, new QTableWidgetItem(QString::fromStdString(p.name)));
    studyTable_->setItem(r, 1, new QTableWidgetItem(limit(p.lowerFactor, p.lowerOpen)));
    studyTable_->setItem(r, 2, new QTableWidgetItem(limit(p.upperFactor, p.upperOpen)));
  }
  const bool ok = a.termination == Termination::Converged &&
                  out.monteCarlo.termination == Termination::Converged;
  QString text = tr("Domain of attraction: %1 fits in %2 s (%3).")
                     .arg(a.fits)
                     .arg(a.seconds, 0, 'f', 1)
                     .arg(QString::fromStdString(a.message));
  if (a.termination == Termination::Converged)
    text += tr(" Monte-Carlo: %1 of %2 runs succeeded (%3 %) in %4 s.")
                .arg(out.monteCarlo.successes)
                .arg(out.monteCarlo.completed)
                .arg(100.0 * out.monteCarlo.successRate(), 0, 'f', 1)
                .arg(out.monteCarlo.seconds, 0, 'f', 1);
  if (!ok && (a.termination == Termination::Cancelled ||
              out.monteCarlo.termination == Termination::Cancelled))
    text += tr(" Cancelled.");
  studySummary_->setText(text);
  progress_->setValue(ok ? 1000 : 0);
  emit studyFinished(ok);
}

}  // namespace flexarm
