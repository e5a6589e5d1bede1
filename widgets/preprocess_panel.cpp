#include "widgets/preprocess_panel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QLabel>
#include <QProgressBar>
#include <QPushButton>
#include <QScrollArea>
#include <QSpinBox>
#include <QTimer>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <chrono>
#include <cmath>
#include <qcustomplot.h>

#include "widgets/plots/plot_tools.h"
#include "widgets/timing_table.h"

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

// Values of a channel without the instants where it was not sampled (irregular logs).
std::vector<double> sampled(const std::vector<double>& v) {
  std::vector<double> out;
  out.reserve(v.size());
  for (double x : v)
    if (!std::isnan(x)) out.push_back(x);
  return out;
}

}  // namespace

PreprocessPanel::PreprocessPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), resample_(new QGroupBox(this)),
      rate_(new QDoubleSpinBox(this)), method_(new QComboBox(this)),
      maxGap_(new QDoubleSpinBox(this)), timing_(new TimingTable(this)),
      differentiate_(new QCheckBox(this)),
      factor_(new QSpinBox(this)), filter_(new QComboBox(this)), detrend_(new QComboBox(this)),
      channel_(new QComboBox(this)), plot_(new QCustomPlot(this)), summary_(new QLabel(this)),
      busy_(new QProgressBar(this)), cancel_(new QPushButton(tr("Cancel"), this)),
      apply_(new QPushButton(tr("Apply"), this)), reset_(new QPushButton(tr("Reset"), this)),
      debounce_(new QTimer(this)) {
  setObjectName("preprocessPanel");
  resample_->setObjectName("resampleGroup");
  resample_->setTitle(tr("Resample onto a uniform grid"));
  resample_->setCheckable(true);
  resample_->setChecked(false);
  resample_->setToolTip(tr("Any rate by a rational factor (polyphase FIR, >= 80 dB from the lower "
                           "Nyquist frequency); required for a log whose time stamps jitter, skip, "
                           "repeat or run backwards"));
  rate_->setObjectName("resampleRateSpin");
  rate_->setToolTip(tr("Sample rate after resampling [Hz]"));
  rate_->setRange(0.001, 1e6);
  rate_->setDecimals(3);
  rate_->setSuffix(" Hz");
  rate_->setValue(2000.0);
  method_->setObjectName("resampleMethodCombo");
  method_->addItem(tr("Band-limited (exact for short gaps)"), "bandlimited");
  method_->addItem(tr("PCHIP (monotone cubic)"), "pchip");
  method_->addItem(tr("Linear"), "linear");
  method_->setToolTip(tr("How irregular time stamps are filled onto the grid"));
  maxGap_->setObjectName("maxGapSpin");
  maxGap_->setRange(0.0, 1e6);
  maxGap_->setDecimals(3);
  maxGap_->setSuffix(" ms");
  maxGap_->setSpecialValueText(tr("ten sample intervals"));
  maxGap_->setToolTip(tr("A longer gap is refused with its place"));
  auto* resampleForm = new QFormLayout(resample_);
  resampleForm->addRow(tr("Rate"), rate_);
  resampleForm->addRow(tr("Irregular stamps by"), method_);
  resampleForm->addRow(tr("Longest gap bridged"), maxGap_);
  timing_->setMaximumHeight(150);
  differentiate_->setText(tr("Motor velocity from the angle (d/dt, becomes the output)"));
  differentiate_->setObjectName("differentiateCheck");
  differentiate_->setToolTip(tr("The output becomes d/dt of the motor angle [rad/s], the motor "
                                "velocity the models (5.3) predict"));
  factor_->setRange(1, 1000);
  factor_->setValue(10);
  factor_->setObjectName("factorSpin");
  factor_->setToolTip(tr("Keep every N-th sample; the seed decimates 2 kHz by 10 (Section 5.1)"));
  filter_->setObjectName("filterCombo");
  filter_->addItem(tr("FIR, linear phase, >= 80 dB above new Nyquist"), "fir");
  filter_->addItem(tr("Chebyshev I order 8, zero phase (as MATLAB decimate)"), "chebyshev");
  filter_->addItem(tr("None (aliasing)"), "none");
  filter_->setToolTip(tr("Low-pass filter before decimating, so that nothing above the new "
                         "Nyquist frequency folds into the band (Section 5.1)"));
  detrend_->setObjectName("detrendCombo");
  detrend_->addItem(tr("Keep"), "none");
  detrend_->addItem(tr("Remove means"), "mean");
  detrend_->addItem(tr("Remove linear trends"), "linear");
  detrend_->setCurrentIndex(1);
  detrend_->setToolTip(tr("Remove the means or linear trends of input and output: the models "
                          "(4.1) describe deviations"));
  channel_->setObjectName("spectrumChannelCombo");
  channel_->setToolTip(tr("Channel whose amplitude spectrum is drawn before and after"));

  auto* form = new QFormLayout;
  form->addRow(differentiate_);
  form->addRow(tr("Decimation factor"), factor_);
  form->addRow(tr("Anti-alias filter"), filter_);
  form->addRow(tr("Input/output means"), detrend_);
  form->addRow(tr("Spectrum of"), channel_);

  plot_->setObjectName("spectrumPlot");
  plot_->setMinimumSize(280, 240);  // tall enough for its amplitude axis' label
  for (QCPAxis* a : {plot_->xAxis, plot_->yAxis}) {
    a->setScaleType(QCPAxis::stLogarithmic);
    a->setTicker(QSharedPointer<QCPAxisTickerLog>(new QCPAxisTickerLog));
    a->setNumberFormat("eb");
    a->setNumberPrecision(0);
  }
  plot_->xAxis->setLabel(tr("frequency [Hz]"));
  plot_->yAxis->setLabel(tr("amplitude per bin"));
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(plot_);
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
  placeLegendAbove(plot_);  // never over the passband

  summary_->setObjectName("preprocessSummary");
  summary_->setWordWrap(true);
  busy_->setRange(0, 0);
  busy_->setVisible(false);
  cancel_->setVisible(false);
  apply_->setObjectName("applyButton");
  reset_->setObjectName("resetButton");
  apply_->setToolTip(tr("Apply the preprocessing to the log (undoable); fits use the result"));
  reset_->setToolTip(tr("Back to the log as read"));
  cancel_->setToolTip(tr("Stop the preprocessing; the log stays as it was"));
  apply_->setEnabled(false);
  auto* buttons = new QHBoxLayout;
  buttons->addWidget(busy_, 1);
  buttons->addWidget(cancel_);
  buttons->addStretch(1);
  buttons->addWidget(reset_);
  buttons->addWidget(apply_);

  // The settings, report and spectra scroll when the dock is short (a 1366x768 screen);
  // the buttons stay in view.
  auto* content = new QWidget(this);
  auto* inner = new QVBoxLayout(content);
  inner->setContentsMargins(0, 0, 0, 0);
  inner->addWidget(resample_);
  timingLabel_ = new QLabel(content);
  timingLabel_->setObjectName("timingLabel");
  timingLabel_->setWordWrap(true);
  inner->addWidget(timingLabel_);
  inner->addWidget(timing_);
  inner->addLayout(form);
  inner->addWidget(plot_, 1);
  inner->addWidget(summary_);
  auto* scroll = new QScrollArea(this);
  scroll->setObjectName("preprocessScroll");
  scroll->setWidget(content);
  scroll->setWidgetResizable(true);
  scroll->setFrameShape(QFrame::NoFrame);
  scroll->setHorizontalScrollBarPolicy(Qt::ScrollBarAlwaysOff);
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(scroll, 1);
  layout->addLayout(buttons);

  debounce_->setSingleShot(true);
  debounce_->setInterval(150);
  connect(debounce_, &QTimer::timeout, this, &PreprocessPanel::preview);
  connect(differentiate_, &QCheckBox::toggled, this, [this] {
    refillChannels();
    schedulePreview();
  });
  connect(factor_, QOverload<int>::of(&QSpinBox::valueChanged), this, &PreprocessPanel::schedulePreview);
  connect(resample_, &QGroupBox::toggled, this, &PreprocessPanel::schedulePreview);
  for (QDoubleSpinBox* b : {rate_, maxGap_})
    connect(b, QOverload<double>::of(&QDoubleSpinBox::valueChanged), this, &PreprocessPanel::schedulePreview);
  connect(method_, QOverload<int>::of(&QComboBox::currentIndexChanged), this, &PreprocessPanel::schedulePreview);
  connect(timing_, &TimingTable::timeSelected, this, &PreprocessPanel::timeSelected);
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
  connect(workspace_, &Workspace::logChanged, this, &PreprocessPanel::onLogChanged);
  onLogChanged();
}

void PreprocessPanel::showTiming(const std::vector<TimingReport>& reports) {
  timing_->setReports(reports);
  // A log with regular stamps says so in a line; the table's room goes to the spectra.
  const bool events = timing_->rowCount() > 0;
  timing_->setVisible(events);
  timingLabel_->setText(events ? tr("Time stamps (click a row to show it in the Log panel):")
                               : tr("Time stamps: regular (no jitter, gap, duplicate or reversal)."));
}

void PreprocessPanel::onLogChanged() {
  result_.reset();
  showTiming({});
  const IdData* raw = workspace_->raw();
  // A log with irregular time stamps cannot be used without resampling: the step is on.
  const bool irregular = raw && !raw->isUniform();
  {
    QSignalBlocker block(resample_), blockRate(rate_);
    resample_->setCheckable(!irregular);
    if (!irregular) resample_->setChecked(false);
    if (raw) {
      const double rate = raw->sampleRateHz();
      const double digits = std::pow(10.0, std::floor(std::log10(rate)) - 5.0);
      rate_->setValue(std::round(rate / digits) * digits);
    }
  }
  refillChannels();
  schedulePreview();
}

QString PreprocessPanel::summaryText() const { return summary_->text(); }

PreprocessOptions PreprocessPanel::options() const {
  PreprocessOptions o;
  if (!resample_->isCheckable() || resample_->isChecked()) {
    UniformGridOptions u;
    u.rateHz = rate_->value();
    u.method = *interpolationMethodFromString(method_->currentData().toString().toStdString());
    u.maxGapSeconds = maxGap_->value() / 1000.0;
    o.resample = u;
  }
  o.differentiateAngle = differentiate_->isChecked() && differentiate_->isEnabled();
  o.decimation.factor = factor_->value();
  o.decimation.filter = *antiAliasFilterFromString(filter_->currentData().toString().toStdString());
  o.detrend = *detrendFromString(detrend_->currentData().toString().toStdString());
  return o;
}

void PreprocessPanel::setOptions(const PreprocessOptions& o) {
  if (resample_->isCheckable()) resample_->setChecked(o.resample.has_value());
  if (o.resample) {
    if (o.resample->rateHz > 0.0) rate_->setValue(o.resample->rateHz);
    method_->setCurrentIndex(method_->findData(QString(toString(o.resample->method))));
    maxGap_->setValue(o.resample->maxGapSeconds * 1000.0);
  }
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
      PreprocessResult r = runPreprocess(*input, o);
      if (r.resampling) {
        for (const auto& g : r.resampling->groups) out.timing.push_back(g.timing);
        out.resampling = QString::fromStdString(r.resampling->message);
      }
      if (r.termination != Termination::Converged) {
        out.error = QString::fromStdString(r.message);
      } else {
        auto result = std::make_shared<IdData>(std::move(r.data));
        // Before: the log as read (irregular stamps: its samples at the nominal interval).
        const bool derive = o.differentiateAngle && input->isUniform();
        const IdData beforeData = derive ? addDerivative(*input) : *input;
        // Both spectra at one frequency resolution: a broadband level per bin grows with the
        // square root of the bin width, so at different resolutions before and after would
        // differ by sqrt(decimation) inside the passband with nothing changed there.
        int afterLength = 0;
        if (const Channel* c = result->channel(channel)) {
          out.after = amplitudeSpectrum(c->values, result->sampleTime);
          out.unit = QString::fromStdString(c->unit);
          if (out.after.frequencyHz.size() > 1)
            afterLength = 2 * static_cast<int>(out.after.frequencyHz.size() - 1);
        }
        if (const Channel* c = beforeData.channel(channel)) {
          const int beforeLength =
              afterLength > 0 ? static_cast<int>(std::lround(afterLength * result->sampleTime /
                                                             beforeData.sampleTime))
                              : 0;
          out.before = amplitudeSpectrum(sampled(c->values), beforeData.sampleTime, beforeLength);
          if (out.unit.isEmpty()) out.unit = QString::fromStdString(c->unit);
        }
        if (out.after.frequencyHz.size() > 1) out.binHz = out.after.frequencyHz[1];
        out.data = std::move(result);
      }
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
  showTiming(out.timing);
  if (!out.error.isEmpty() || !out.data) {
    result_.reset();
    summary_->setText(tr("Preprocessing failed: %1").arg(out.error));
    emit previewReady();
    return;
  }
  result_ = out.data;
  resultOptions_ = options();
  const IdData* raw = workspace_->raw();
  setSpectrum(plot_->graph(0), out.before);
  setSpectrum(plot_->graph(1), out.after);
  plot_->yAxis->setLabel(out.unit.isEmpty() ? tr("amplitude per bin")
                                            : tr("amplitude per bin [%1]").arg(out.unit));
  plot_->rescaleAxes();
  auto* nyq = qobject_cast<QCPItemStraightLine*>(plot_->item(0));
  const double nyquist = 0.5 * result_->sampleRateHz();
  if (nyq) {
    nyq->point1->setCoords(nyquist, 1e-30);
    nyq->point2->setCoords(nyquist, 1);
    nyq->setVisible(result_->sampleRateHz() < raw->sampleRateHz() * (1.0 - 1e-9));
  }
  plot_->replot();
  QString text = tr("%1 Hz -> %2 Hz, %3 -> %4 samples (new Nyquist %5 Hz, dashed); %6 ms")
                     .arg(raw->sampleRateHz(), 0, 'g', 6)
                     .arg(result_->sampleRateHz(), 0, 'g', 6)
                     .arg(raw->samples())
                     .arg(result_->samples())
                     .arg(nyquist, 0, 'g', 4)
                     .arg(out.seconds * 1000.0, 0, 'f', 0);
  if (out.binHz > 0)
    text += tr("\nSpectrum: Welch amplitude, a sinusoid of amplitude a peaks at a; before and "
               "after at the same %1 Hz bins, so inside the passband they agree and differ only "
               "where the anti-alias filter cuts.")
                .arg(out.binHz, 0, 'g', 3);
  if (!out.resampling.isEmpty()) text += tr("\nResampled: %1").arg(out.resampling);
  summary_->setText(text);
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
