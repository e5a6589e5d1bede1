#include "widgets/preprocess_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QFormLayout>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <chrono>
#include <qcustomplot.h>

namespace flexarm {
namespace {

void setSpectrum(QCPGraph* g, const AmplitudeSpectrum& s) {
  QVector<double> f, a;
  for (std::size_t i = 1; i < s.frequencyHz.size(); ++i) {  // skip DC on log axes
    if (!(s.amplitude[i] > 0)) continue;
    f.push_back(s.frequencyHz[i]);
    a.push_back(s.amplitude[i]);
  }
  g->setData(f, a, true);
}

}  // namespace

PreprocessPanel::PreprocessPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), differentiate_(new QCheckBox(this)),
      factor_(new QSpinBox(this)), filter_(new QComboBox(this)), detrend_(new QComboBox(this)),
      channel_(new QComboBox(this)), plot_(new QCustomPlot(this)), summary_(new QLabel(this)),
      busy_(new QProgressBar(this)), cancel_(new QPushButton(tr("Cancel"), this)),
      apply_(new QPushButton(tr("Apply"), this)), reset_(new QPushButton(tr("Reset"), this)),
      debounce_(new QTimer(this)) {
  setObjectName("preprocessPanel");
  differentiate_->setText(tr("Motor velocity from the angle (d/dt, becomes the output)"));
  differentiate_->setObjectName("differentiateCheck");
  factor_->setRange(1, 1000);
  factor_->setValue(10);
  factor_->setObjectName("factorSpin");
  factor_->setToolTip(tr("Keep every N-th sample; the seed decimates 2 kHz by 10 (Section 5.1)"));
  filter_->setObjectName("filterCombo");
  filter_->addItem(tr("FIR, linear phase, >= 80 dB above new Nyquist"), "fir");
  filter_->addItem(tr("Chebyshev I order 8, zero phase (as MATLAB decimate)"), "chebyshev");
  filter_->addItem(tr("None (aliasing)"), "none");
  detrend_->setObjectName("detrendCombo");
  detrend_->addItem(tr("Keep"), "none");
  detrend_->addItem(tr("Remove means"), "mean");
  detrend_->addItem(tr("Remove linear trends"), "linear");
  detrend_->setCurrentIndex(1);
  channel_->setObjectName("spectrumChannelCombo");

  auto* form = new QFormLayout;
  form->addRow(differentiate_);
  form->addRow(tr("Decimation factor"), factor_);
  form->addRow(tr("Anti-alias filter"), filter_);
  form->addRow(tr("Input/output means"), detrend_);
  form->addRow(tr("Spectrum of"), channel_);

  plot_->setObjectName("spectrumPlot");
  plot_->setMinimumSize(280, 200);
  for (QCPAxis* a : {plot_->xAxis, plot_->yAxis}) {
    a->setScaleType(QCPAxis::stLogarithmic);
    a->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
    a->setNumberFormat("eb");
    a->setNumberPrecision(0);
  }
  plot_->xAxis->setLabel(tr("frequency [Hz]"));
  plot_->yAxis->setLabel(tr("amplitude"));
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  auto* before = plot_->addGraph();
  before->setName(tr("before"));
  before->setPen(QPen(QColor(150, 150, 150), 1));
  auto* after = plot_->addGraph();
  after->setName(tr("after"));
  after->setPen(QPen(QColor(31, 119, 180), 1.3));
  auto* nyq = new QCPItemStraightLine(plot_);
  nyq->setObjectName("nyquistLine");
  nyq->setPen(QPen(QColor(200, 40, 40), 1, Qt::DashLine));
  nyq->setVisible(false);
  plot_->legend->setVisible(true);
  plot_->legend->setFont(QFont(font().family(), 8));

  summary_->setObjectName("preprocessSummary");
  summary_->setWordWrap(true);
  busy_->setRange(0, 0);
  busy_->setVisible(false);
  cancel_->setVisible(false);
  apply_->setObjectName("applyButton");
  reset_->setObjectName("resetButton");
  apply_->setEnabled(false);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(busy_, 1);
  buttons->addWidget(cancel_);
  buttons->addStretch(1);
  buttons->addWidget(reset_);
  buttons->addWidget(apply_);

  auto* layout = new QVBoxLayout(this);
  layout->addLayout(form);
  layout->addWidget(plot_, 1);
  layout->addWidget(summary_);
  layout->addLayout(buttons);

  debounce_->setSingleShot(true);
  debounce_->setInterval(150);
  connect(debounce_, &QTimer::timeout, this, &PreprocessPanel::preview);
  connect(differentiate_, &QCheckBox::toggled, this, [this] {
    refillChannels();
    schedulePreview();
  });
  connect(factor_, QOverload<int>::of(&QSpinBox::valueChanged), this, &PreprocessPanel::schedulePreview);
  for (QComboBox* c : {filter_, detrend_, channel_})
    connect(c, QOverload<int>::of(&QComboBox::currentIndexChanged), this, &PreprocessPanel::schedulePreview);
  connect(cancel_, &QPushButton::clicked, this, [this] {
    ++generation_;  // the running result will be dropped
    busy_->setVisible(false);
    cancel_->setVisible(false);
    summary_->setText(tr("Cancelled."));
  });
  connect(apply_, &QPushButton::clicked, this, &PreprocessPanel::apply);
  connect(reset_, &QPushButton::clicked, this, &PreprocessPanel::reset);
  connect(&watcher_, &QFutureWatcher<Outcome>::finished, this, &PreprocessPanel::onFinished);
  connect(workspace_, &Workspace::logChanged, this, [this] {
    result_.reset();
    refillChannels();
    schedulePreview();
  });
  refillChannels();
}

PreprocessOptions PreprocessPanel::options() const {
  PreprocessOptions o;
  o.differentiateAngle = differentiate_->isChecked() && differentiate_->isEnabled();
  o.decimation.factor = factor_->value();
  o.decimation.filter = *antiAliasFilterFromString(filter_->currentData().toString().toStdString());
  o.detrend = *detrendFromString(detrend_->currentData().toString().toStdString());
  return o;
}

void PreprocessPanel::setOptions(const PreprocessOptions& o) {
  differentiate_->setChecked(o.differentiateAngle);
  factor_->setValue(o.decimation.factor);
  filter_->setCurrentIndex(filter_->findData(QString(toString(o.decimation.filter))));
  detrend_->setCurrentIndex(detrend_->findData(QString(toString(o.detrend))));
}

void PreprocessPanel::refillChannels() {
  const IdData* raw = workspace_->raw();
  const QString keep = channel_->currentText();
  QSignalBlocker block(channel_);
  channel_->clear();
  if (!raw) return;
  differentiate_->setEnabled(raw->channel(columns::kMotorAngle) != nullptr);
  for (const auto& c : raw->channels) channel_->addItem(QString::fromStdString(c.name));
  if (differentiate_->isChecked() && differentiate_->isEnabled() && !raw->channel(columns::kMotorVelocity))
    channel_->addItem(columns::kMotorVelocity);
  int idx = channel_->findText(keep);
  if (idx < 0 && raw->input()) idx = channel_->findText(QString::fromStdString(raw->input()->name));
  channel_->setCurrentIndex(std::max(0, idx));
}

void PreprocessPanel::schedulePreview() {
  apply_->setEnabled(false);
  debounce_->start();
}

void PreprocessPanel::preview() {
  debounce_->stop();
  const IdData* raw = workspace_->raw();
  if (!raw) return;
  const PreprocessOptions o = options();
  std::string why;
  if (!o.isValid(&why)) {
    summary_->setText(QString::fromStdString(why));
    return;
  }
  if (watcher_.isRunning()) {  // let it finish; the newest request runs afterwards
    debounce_->start();
    return;
  }
  auto input = std::make_shared<IdData>(*raw);
  const std::string channel = channel_->currentText().toStdString();
  running_ = ++generation_;
  busy_->setVisible(true);
  cancel_->setVisible(true);
  summary_->setText(tr("Computing..."));
  watcher_.setFuture(QtConcurrent::run([input, o, channel]() {
    Outcome out;
    const auto t0 = std::chrono::steady_clock::now();
    try {
      auto result = std::make_shared<IdData>(preprocess(*input, o));
      const IdData beforeData = o.differentiateAngle ? addDerivative(*input) : *input;
      if (const Channel* c = beforeData.channel(channel))
        out.before = amplitudeSpectrum(c->values, beforeData.sampleTime);
      if (const Channel* c = result->channel(channel))
        out.after = amplitudeSpectrum(c->values, result->sampleTime);
      out.data = std::move(result);
    } catch (const std::exception& e) {
      out.error = QString::fromStdString(e.what());
    }
    out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return out;
  }));
}

void PreprocessPanel::onFinished() {
  Outcome out = watcher_.result();
  if (running_ != generation_) return;  // cancelled or superseded
  busy_->setVisible(false);
  cancel_->setVisible(false);
  if (!out.error.isEmpty() || !out.data) {
    summary_->setText(tr("Preprocessing failed: %1").arg(out.error));
    return;
  }
  result_ = out.data;
  resultOptions_ = options();
  setSpectrum(plot_->graph(0), out.before);
  setSpectrum(plot_->graph(1), out.after);
  plot_->rescaleAxes();
  auto* nyq = qobject_cast<QCPItemStraightLine*>(plot_->item(0));
  const double nyquist = 0.5 * result_->sampleRateHz();
  if (nyq) {
    nyq->point1->setCoords(nyquist, 1e-30);
    nyq->point2->setCoords(nyquist, 1);
    nyq->setVisible(resultOptions_.decimation.factor > 1);
  }
  plot_->replot();
  const IdData* raw = workspace_->raw();
  summary_->setText(tr("%1 Hz -> %2 Hz, %3 -> %4 samples (new Nyquist %5 Hz, dashed); %6 ms")
                        .arg(raw->sampleRateHz(), 0, 'g', 6)
                        .arg(result_->sampleRateHz(), 0, 'g', 6)
                        .arg(raw->samples())
                        .arg(result_->samples())
                        .arg(nyquist, 0, 'g', 4)
                        .arg(out.seconds * 1000.0, 0, 'f', 0));
  apply_->setEnabled(true);
  emit previewReady();
}

void PreprocessPanel::apply() {
  if (!result_) return;
  workspace_->setPreprocessed(*result_, resultOptions_);
  summary_->setText(summary_->text() + tr(" - applied"));
}

void PreprocessPanel::reset() { workspace_->clearPreprocessed(); }

}  // namespace flexarm
