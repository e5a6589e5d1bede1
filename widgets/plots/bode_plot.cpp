#include "widgets/plots/bode_plot.h"

#include <QLabel>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <qcustomplot.h>

#include "core/models/analysis.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {
namespace {

constexpr double kPi = 3.14159265358979323846;

double toDb(double magnitude) { return 20.0 * std::log10(std::max(magnitude, 1e-300)); }

void setupLogFrequencyAxis(QCPAxis* axis) {
  axis->setScaleType(QCPAxis::stLogarithmic);
  QSharedPointer<QCPAxisTickerLog> ticker(new QCPAxisTickerLog);
  axis->setTicker(ticker);
  axis->setNumberFormat("eb");
  axis->setNumberPrecision(0);
}

}  // namespace

std::vector<BodeCurve::Extremum> sampledExtrema(const std::vector<double>& omega,
                                               const std::vector<std::complex<double>>& response) {
  std::vector<double> magnitude;
  for (const auto& h : response) magnitude.push_back(std::abs(h));
  std::vector<BodeCurve::Extremum> out;
  if (omega.size() < 3 || omega.size() != magnitude.size() || omega.front() <= 0.0) return out;
  const NotchesPeaks np = magnitudeExtrema(omega, magnitude);
  // The level at a refined frequency: the magnitude in dB interpolated over log-frequency.
  auto levelAt = [&](double w) {
    const auto it = std::lower_bound(omega.begin(), omega.end(), w);
    const std::size_t i = std::clamp<std::size_t>(static_cast<std::size_t>(it - omega.begin()), 1, omega.size() - 1);
    const double t = std::log(w / omega[i - 1]) / std::log(omega[i] / omega[i - 1]);
    return toDb(magnitude[i - 1]) + t * (toDb(magnitude[i]) - toDb(magnitude[i - 1]));
  };
  for (double w : np.notches) out.push_back({w, levelAt(w), false});
  for (double w : np.peaks) out.push_back({w, levelAt(w), true});
  return out;
}

std::vector<BodeCurve::Extremum> curveExtrema(const NotchesPeaks& np,
                                              const std::function<double(double)>& magnitudeAt) {
  std::vector<BodeCurve::Extremum> out;
  for (double w : np.notches) out.push_back({w, toDb(magnitudeAt(w)), false});
  for (double w : np.peaks) out.push_back({w, toDb(magnitudeAt(w)), true});
  return out;
}

std::vector<double> unwrappedPhaseDeg(const std::vector<std::complex<double>>& response) {
  std::vector<double> out(response.size());
  double offset = 0.0, previous = 0.0;
  for (std::size_t i = 0; i < response.size(); ++i) {
    const double p = std::arg(response[i]);
    if (i > 0) {
      const double jump = p - previous;
      if (jump > kPi) offset -= 2 * kPi;
      if (jump < -kPi) offset += 2 * kPi;
    }
    previous = p;
    out[i] = (p + offset) * 180.0 / kPi;
  }
  return out;
}

BodePlot::BodePlot(QWidget* parent)
    : QWidget(parent), plot_(new QCustomPlot(this)), readout_(new QLabel(this)) {
  setObjectName("bodePlot");
  plot_->plotLayout()->clear();
  magRect_ = new QCPAxisRect(plot_);
  phaseRect_ = new QCPAxisRect(plot_);
  plot_->plotLayout()->addElement(0, 0, magRect_);
  plot_->plotLayout()->addElement(1, 0, phaseRect_);
  auto* margins = new QCPMarginGroup(plot_);
  for (QCPAxisRect* r : {magRect_, phaseRect_}) {
    r->setMarginGroup(QCP::msLeft | QCP::msRight, margins);
    setupLogFrequencyAxis(r->axis(QCPAxis::atBottom));
    r->setRangeDrag(Qt::Horizontal | Qt::Vertical);
    r->setRangeZoom(Qt::Horizontal | Qt::Vertical);
  }
  magRect_->axis(QCPAxis::atLeft)->setLabel(tr("magnitude [dB]"));
  phaseRect_->axis(QCPAxis::atLeft)->setLabel(tr("phase [deg]"));
  phaseRect_->axis(QCPAxis::atBottom)->setLabel(tr("frequency [rad/s]"));
  connect(magRect_->axis(QCPAxis::atBottom), QOverload<const QCPRange&>::of(&QCPAxis::rangeChanged),
          phaseRect_->axis(QCPAxis::atBottom), QOverload<const QCPRange&>::of(&QCPAxis::setRange));
  connect(phaseRect_->axis(QCPAxis::atBottom), QOverload<const QCPRange&>::of(&QCPAxis::rangeChanged),
          magRect_->axis(QCPAxis::atBottom), QOverload<const QCPRange&>::of(&QCPAxis::setRange));
  // The legend sits in its own row above the magnitude, never over a peak or notch.
  plot_->legend = new QCPLegend;
  magRect_->insetLayout()->addElement(plot_->legend, Qt::AlignRight | Qt::AlignTop);
  plot_->legend->setLayer("legend");
  plot_->legend->setVisible(true);
  placeLegendAbove(plot_, magRect_);
  plot_->legend->setSelectableParts(QCPLegend::spItems);
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom | QCP::iSelectLegend);
  connect(plot_, &QCustomPlot::legendClick, this,
          [this](QCPLegend*, QCPAbstractLegendItem* item, QMouseEvent*) {
            auto* pli = qobject_cast<QCPPlottableLegendItem*>(item);
            if (!pli) return;
            for (std::size_t i = 0; i < curves_.size(); ++i)
              if (curves_[i].mag == pli->plottable()) setCurveVisible(static_cast<int>(i), !isCurveVisible(static_cast<int>(i)));
          });
  connect(plot_, &QCustomPlot::mousePress, this, &BodePlot::onClick);
  // Double click and the right-click menu reset the zoom to the visible curves.
  PlotTools::install(plot_)->setReset([this] { rescale(); });
  readout_->setObjectName("bodeReadout");
  readout_->setText(tr("Click near a peak or notch to read it; click a legend entry to hide it; "
                       "double click resets the zoom"));
  readout_->setWordWrap(true);
  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(plot_, 1);
  layout->addWidget(readout_);
  setMinimumSize(320, 340);  // magnitude and phase each tall enough for their labels
}

void BodePlot::clear() {
  plot_->clearGraphs();
  curves_.clear();
  plot_->replot();
}

int BodePlot::addCurve(const BodeCurve& curve) {
  Entry e;
  e.curve = curve;
  for (const auto& h : curve.response) e.magnitudeDb.push_back(toDb(std::abs(h)));
  e.phaseDeg = unwrappedPhaseDeg(curve.response);
  if (!curve.extremaKnown) e.curve.extrema = sampledExtrema(curve.frequency, curve.response);
  auto qv = [](const std::vector<double>& v) { return QVector<double>(v.begin(), v.end()); };
  const QVector<double> w = qv(curve.frequency);
  QCPAxis* mx = magRect_->axis(QCPAxis::atBottom);
  QCPAxis* my = magRect_->axis(QCPAxis::atLeft);
  QCPAxis* px = phaseRect_->axis(QCPAxis::atBottom);
  QCPAxis* py = phaseRect_->axis(QCPAxis::atLeft);
  QColor fill = curve.color;
  fill.setAlpha(50);
  auto addBand = [&](QCPAxis* x, QCPAxis* y, std::vector<double> low, std::vector<double> high) {
    auto* lo = plot_->addGraph(x, y);
    auto* hi = plot_->addGraph(x, y);
    lo->setData(w, qv(low), true);
    hi->setData(w, qv(high), true);
    for (auto* g : {lo, hi}) {
      g->setPen(Qt::NoPen);
      g->removeFromLegend();
      g->setSelectable(QCP::stNone);
    }
    hi->setBrush(fill);
    hi->setChannelFillGraph(lo);
    e.band.push_back(lo);
    e.band.push_back(hi);
  };
  const std::size_t n = curve.frequency.size();
  if (curve.magnitudeLow.size() == n && curve.magnitudeHigh.size() == n) {
    std::vector<double> lo(n), hi(n);
    for (std::size_t i = 0; i < n; ++i) {
      lo[i] = toDb(std::max(curve.magnitudeLow[i], 1e-300));
      hi[i] = toDb(curve.magnitudeHigh[i]);
    }
    addBand(mx, my, lo, hi);
  }
  if (curve.phaseLowDeg.size() == n && curve.phaseHighDeg.size() == n) {
    // Bands are given around the wrapped phase; move them with the unwrapping offset.
    std::vector<double> lo(n), hi(n);
    for (std::size_t i = 0; i < n; ++i) {
      const double offset = e.phaseDeg[i] - std::arg(curve.response[i]) * 180.0 / kPi;
      lo[i] = curve.phaseLowDeg[i] + offset;
      hi[i] = curve.phaseHighDeg[i] + offset;
    }
    addBand(px, py, lo, hi);
  }
  e.mag = plot_->addGraph(mx, my);
  e.phase = plot_->addGraph(px, py);
  e.mag->setName(curve.name);
  e.phase->removeFromLegend();
  for (auto [g, y] : {std::pair{e.mag, &e.magnitudeDb}, std::pair{e.phase, &e.phaseDeg}}) {
    g->setData(w, qv(*y), true);
    if (curve.points) {
      g->setLineStyle(QCPGraph::lsNone);
      g->setScatterStyle(QCPScatterStyle(QCPScatterStyle::ssDisc, curve.color, 3));
    } else {
      g->setPen(QPen(curve.color, 1.6));
    }
  }
  curves_.push_back(std::move(e));
  const int index = static_cast<int>(curves_.size()) - 1;
  if (hidden_.contains(curve.name)) setCurveVisible(index, false);  // hidden by the user before
  else rescale();
  return index;
}

void BodePlot::setCurveVisible(int index, bool visible) {
  if (index < 0 || index >= curveCount()) return;
  Entry& e = curves_[static_cast<std::size_t>(index)];
  e.mag->setVisible(visible);
  e.phase->setVisible(visible);
  for (auto* g : e.band) g->setVisible(visible);
  if (auto* item = plot_->legend->itemWithPlottable(e.mag))
    item->setTextColor(visible ? Qt::black : QColor(170, 170, 170));
  // The choice outlives a refresh that draws the curves anew (a tick of SPA, a new level).
  if (visible) hidden_.remove(e.curve.name);
  else hidden_.insert(e.curve.name);
  rescale();  // the axes follow what is shown
}

bool BodePlot::isCurveVisible(int index) const {
  return index >= 0 && index < curveCount() && curves_[static_cast<std::size_t>(index)].mag->visible();
}

void BodePlot::rescale() {
  // The axes span what is shown: the visible curves, and their bands where these stay near
  // them. A band that dives at a notch (-6000 dB where the lower bound nears zero) widens the
  // axis by its 2nd-98th percentile at most, and never by more than the curves' own span.
  struct Span {
    double lo = 1e300, hi = -1e300;
    void add(double v) {
      if (std::isfinite(v)) lo = std::min(lo, v), hi = std::max(hi, v);
    }
    bool valid() const { return lo <= hi; }
  };
  Span frequency, lines[2];
  std::vector<double> bandValues[2];
  QCPAxis* magAxis = magRect_->axis(QCPAxis::atLeft);
  for (const auto& e : curves_) {
    if (!e.mag->visible()) continue;
    for (double w : e.curve.frequency)
      if (w > 0.0) frequency.add(w);
    for (double v : e.magnitudeDb) lines[0].add(v);
    for (double v : e.phaseDeg) lines[1].add(v);
    for (const QCPGraph* g : e.band) {
      const int k = g->valueAxis() == magAxis ? 0 : 1;
      for (auto it = g->data()->constBegin(); it != g->data()->constEnd(); ++it)
        if (std::isfinite(it->value)) bandValues[k].push_back(it->value);
    }
  }
  if (!frequency.valid()) {
    plot_->replot();
    return;
  }
  magRect_->axis(QCPAxis::atBottom)->setRange(frequency.lo, frequency.hi);
  for (int k = 0; k < 2; ++k) {
    Span range = lines[k];
    if (!range.valid()) continue;
    const double span = std::max(range.hi - range.lo, k == 0 ? 10.0 : 20.0);
    std::vector<double>& band = bandValues[k];
    if (!band.empty()) {
      std::sort(band.begin(), band.end());
      const auto at = [&band](double q) { return band[static_cast<std::size_t>(q * static_cast<double>(band.size() - 1))]; };
      range.lo = std::min(range.lo, std::max(at(0.02), range.lo - span));
      range.hi = std::max(range.hi, std::min(at(0.98), range.hi + span));
    }
    const double pad = std::max(1.0, 0.05 * (range.hi - range.lo));
    (k == 0 ? magRect_ : phaseRect_)->axis(QCPAxis::atLeft)->setRange(range.lo - pad, range.hi + pad);
  }
  plot_->replot();
}

std::optional<BodeCurve::Extremum> BodePlot::extremumNear(int index, double w) const {
  if (index < 0 || index >= curveCount()) return std::nullopt;
  std::optional<BodeCurve::Extremum> best;
  double bestDistance = std::log(1.5);
  for (const auto& x : curves_[static_cast<std::size_t>(index)].curve.extrema) {
    const double distance = std::abs(std::log(x.frequency / w));
    if (distance < bestDistance) bestDistance = distance, best = x;
  }
  return best;
}

QString BodePlot::readoutText() const { return readout_->text(); }

void BodePlot::onClick(QMouseEvent* e) {
  if (e->button() != Qt::LeftButton || !magRect_->rect().contains(e->pos()) || curves_.empty())
    return;
  const double w = magRect_->axis(QCPAxis::atBottom)->pixelToCoord(e->position().x());
  const double level = magRect_->axis(QCPAxis::atLeft)->pixelToCoord(e->position().y());
  // The visible curve whose magnitude at w is closest to the click, then its extremum.
  int chosen = -1;
  double closest = 1e300;
  for (int i = 0; i < curveCount(); ++i) {
    if (!isCurveVisible(i)) continue;
    const Entry& c = curves_[static_cast<std::size_t>(i)];
    const auto it = std::lower_bound(c.curve.frequency.begin(), c.curve.frequency.end(), w);
    if (it == c.curve.frequency.end()) continue;
    const double d = std::abs(c.magnitudeDb[static_cast<std::size_t>(it - c.curve.frequency.begin())] - level);
    if (d < closest) closest = d, chosen = i;
  }
  if (chosen < 0) return;
  if (auto x = extremumNear(chosen, w)) {
    const auto& c = curves_[static_cast<std::size_t>(chosen)];
    readout_->setText(tr("%1: %2 at %3 rad/s (%4 Hz), %5 dB")
                          .arg(c.curve.name)
                          .arg(x->peak ? tr("peak") : tr("notch"))
                          .arg(x->frequency, 0, 'f', 1)
                          .arg(x->frequency / (2 * kPi), 0, 'f', 2)
                          .arg(x->levelDb, 0, 'f', 1));
    emit extremumPicked(chosen, x->frequency, x->levelDb);
  } else {
    readout_->setText(tr("%1: no peak or notch near %2 rad/s")
                          .arg(curves_[static_cast<std::size_t>(chosen)].curve.name)
                          .arg(w, 0, 'f', 1));
  }
}

bool BodePlot::exportTo(const QString& path, QString* why) const {
  return PlotTools::of(plot_)->exportTo(path, why);
}

}  // namespace flexarm
