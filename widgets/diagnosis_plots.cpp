// The Diagnosis panel's view of a result: the plots built once per result, and what the
// playhead's time shows (curves up to it, the decision table, the verdict).
#include <QLabel>
#include <QTableWidget>
#include <cmath>
#include <qcustomplot.h>

#include "widgets/diagnosis_panel.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {

namespace {

const QColor kColors[] = {QColor(30, 90, 200), QColor(200, 120, 0), QColor(40, 150, 60),
                          QColor(150, 40, 160), QColor(110, 110, 110)};
const QColor kAlarm(200, 40, 40), kHealthy(40, 140, 60), kDetected(220, 140, 0);

QCPGraph* curve(QCustomPlot* p, QCPAxisRect* rect, const QString& name, const QColor& c,
                Qt::PenStyle style = Qt::SolidLine) {
  QCPGraph* g = p->addGraph(rect->axis(QCPAxis::atBottom), rect->axis(QCPAxis::atLeft));
  g->setName(name);
  g->setPen(QPen(c, 1.3, style));
  return g;
}

void level(QCustomPlot* p, QCPAxisRect* rect, double y, const QColor& c) {
  auto* line = new QCPItemStraightLine(p);
  line->setClipAxisRect(rect);
  line->point1->setAxes(rect->axis(QCPAxis::atBottom), rect->axis(QCPAxis::atLeft));
  line->point2->setAxes(rect->axis(QCPAxis::atBottom), rect->axis(QCPAxis::atLeft));
  line->point1->setCoords(0.0, y);
  line->point2->setCoords(1.0, y);
  line->setPen(QPen(c, 1.0, Qt::DashLine));
}

QString seconds(double t) { return QString::number(t, 'f', 2) + " s"; }

}  // namespace

void DiagnosisPanel::buildPlots() {
  const DiagnosisResult& r = shownRun_->result;
  shown_.clear();
  shownSample_ = static_cast<std::size_t>(-1);
  for (QCustomPlot* p : {estimates_, cusum_, hypothesis_, timeline_}) {
    p->clearGraphs();
    p->clearItems();
  }
  if (r.time.empty()) return;
  const double t0 = r.time.front(), t1 = r.time.back();
  auto keep = [this](QCPGraph* g, std::vector<double> y) { shown_.push_back(Shown{g, std::move(y)}); };

  // One axis rect per parameter: the estimate and its smoothed value as % of theta_0, with the
  // robust test's band.
  QCPLayoutGrid* grid = estimates_->plotLayout();
  // removeAt empties a cell without removing it (elementCount stays): walk the cells once,
  // then drop the empty rows.
  for (int k = grid->elementCount() - 1; k > 0; --k)
    if (grid->elementAt(k)) grid->removeAt(k);
  grid->simplify();
  const TestTrace* robust = r.trace(DiagnosisTest::Robust);
  for (std::size_t i = 0; i < r.parameters.size(); ++i) {
    QCPAxisRect* rect = i == 0 ? estimates_->axisRect() : new QCPAxisRect(estimates_);
    if (i > 0) grid->addElement(static_cast<int>(i), 0, rect);
    rect->axis(QCPAxis::atLeft)->setLabel(QString::fromStdString(r.parameters[i].name) + " (%)");
    rect->axis(QCPAxis::atBottom)->setLabel(i + 1 == r.parameters.size() ? tr("time (s)") : QString());
    rect->axis(QCPAxis::atBottom)->setRange(t0, t1);
    const double nominal = r.theta0[i];
    auto percent = [nominal](const std::vector<double>& v) {
      std::vector<double> out(v.size());
      for (std::size_t k = 0; k < v.size(); ++k) out[k] = 100.0 * (v[k] / nominal - 1.0);
      return out;
    };
    keep(curve(estimates_, rect, tr("estimate"), kColors[0]), percent(r.estimates.theta[i]));
    double span = 5.0;
    if (robust && i < r.smoothed.size()) {
      keep(curve(estimates_, rect, tr("smoothed"), Qt::black), percent(r.smoothed[i]));
      std::vector<double> band(r.time.size());
      for (std::size_t k = 0; k < band.size(); ++k) band[k] = 100.0 * robust->threshold[i][k] / std::abs(nominal);
      for (std::size_t k = band.size() / 10; k < band.size(); ++k) span = std::max(span, 1.5 * band[k]);
      keep(curve(estimates_, rect, tr("band"), kAlarm, Qt::DashLine), band);
      for (double& b : band) b = -b;
      keep(curve(estimates_, rect, QString(), kAlarm, Qt::DashLine), band);
    }
    for (double v : percent(r.estimates.theta[i])) span = std::max(span, 1.1 * std::abs(v));
    rect->axis(QCPAxis::atLeft)->setRange(-std::min(span, 60.0), std::min(span, 60.0));
    // Three short rects: labels at -span, 0, span only, or they overlap.
    rect->axis(QCPAxis::atLeft)->ticker()->setTickStepStrategy(QCPAxisTicker::tssMeetTickCount);
    rect->axis(QCPAxis::atLeft)->ticker()->setTickCount(2);
    level(estimates_, rect, 0.0, kColors[4]);
  }
  keepRectsTall(estimates_, 110);

  // cap: the axis stops at cap times the level, so that the approach to it stays readable.
  auto simple = [&](QCustomPlot* p, const TestTrace* t, bool ratio, double line, double cap,
                    const QString& yLabel) {
    if (!t) return;
    QCPAxisRect* rect = p->axisRect();
    rect->axis(QCPAxis::atBottom)->setRange(t0, t1);
    double top = 1.5 * line;
    for (std::size_t q = 0; q < t->columns.size(); ++q) {
      const auto& y = ratio ? t->ratio[q] : t->statistic[q];
      for (std::size_t k = y.size() / 10; k < y.size(); ++k)
        if (std::isfinite(y[k])) top = std::max(top, 1.1 * y[k]);
      keep(curve(p, rect, QString::fromStdString(t->columns[q]), kColors[q % 5]), y);
    }
    rect->axis(QCPAxis::atLeft)->setRange(ratio ? 0.0 : std::max(0.0, 2.0 - top), std::min(top, cap * line));
    rect->axis(QCPAxis::atLeft)->setLabel(yLabel);
    level(p, rect, line, kAlarm);
  };
  simple(cusum_, r.trace(DiagnosisTest::Cusum), true, 1.0, 10.0, tr("CUSUM g / h [-]"));
  simple(hypothesis_, r.trace(DiagnosisTest::Hypothesis), false, r.options.hypothesisThreshold, 3.0,
         tr("hypothesis T [-]"));

  // Alarm timeline: a row per test and one for the decision, raised while NF is rejected.
  QCPAxisRect* rect = timeline_->axisRect();
  rect->axis(QCPAxis::atBottom)->setRange(t0, t1);
  QSharedPointer<QCPAxisTickerText> ticker(new QCPAxisTickerText);
  for (std::size_t k = 0; k <= r.tests.size(); ++k) {
    const bool decision = k == r.tests.size();
    const TestOutcome& o = decision ? r.decision : r.outcomes[k];
    std::vector<double> y(r.time.size());
    for (std::size_t n = 0; n < y.size(); ++n) y[n] = static_cast<double>(k) + ((o.statement[n] & 1u) ? 0.0 : 0.7);
    QCPGraph* g = curve(timeline_, rect, decision ? tr("decision") : QString(toString(r.tests[k].test)),
                        decision ? kAlarm : kColors[k % 5]);
    g->setLineStyle(QCPGraph::lsStepLeft);
    g->setPen(QPen(g->pen().color(), decision ? 2.5 : 1.8));
    keep(g, y);
    ticker->addTick(static_cast<double>(k) + 0.35, decision ? tr("decision") : QString(toString(r.tests[k].test)));
  }
  rect->axis(QCPAxis::atLeft)->setTicker(ticker);
  rect->axis(QCPAxis::atLeft)->setRange(-0.3, static_cast<double>(r.tests.size()) + 1.0);
  for (PlayheadCursor* c : cursors_) c->attach();

  // Thresholds and where they come from.
  QStringList th;
  const DiagnosisOptions& o = r.options;
  for (const auto& t : r.tests) {
    QStringList values;
    if (t.test == DiagnosisTest::Hypothesis) {
      values << QString::number(o.hypothesisThreshold, 'g', 4);
    } else if (t.test == DiagnosisTest::Joint) {
      values << QString("%1 x chi2 quantile").arg(o.jointScale, 0, 'g', 3);
    } else {
      for (std::size_t q = 0; q < t.columns.size(); ++q) {
        const double base = t.test == DiagnosisTest::Classical ? o.classicalK
                            : t.test == DiagnosisTest::Robust  ? o.robustK
                                                               : o.cusumAlpha2;
        values << QString("%1 %2").arg(QString::fromStdString(t.columns[q]))
                      .arg(base * o.thresholdScale(t.test, q), 0, 'g', 3);
      }
    }
    th << QString("%1: %2").arg(toString(t.test)).arg(values.join(", "));
  }
  const QString from = shownRun_->calibration
                           ? tr("calibrated: %1").arg(QString::fromStdString(shownRun_->calibration->message))
                           : storedCalibration_.is_object()
                                 ? tr("calibrated: %1").arg(QString::fromStdString(storedCalibration_.value("message", std::string())))
                                 : QString::fromStdString(thresholdsProvenance(r.options));
  thresholds_->setText(tr("Thresholds (sigma units, CUSUM alpha_2, level): %1. %2. Reference: %3. "
                          "Temperature: %4. %5")
                           .arg(th.join("; "), from, QString::fromStdString(r.referenceSource),
                                QString::fromStdString(r.temperature.message.empty()
                                                           ? std::string("not stated")
                                                           : r.temperature.message),
                                QString::fromStdString(r.modelCheck.message)));
  for (QCustomPlot* p : {cusum_, hypothesis_}) showLegendAbove(p);  // above the data, no curve under it
  for (QCustomPlot* p : {estimates_, cusum_, hypothesis_, timeline_}) p->replot();
}

void DiagnosisPanel::showAt(double t) {
  if (!shownRun_ || shownRun_->result.time.empty()) return;
  const DiagnosisResult& r = shownRun_->result;
  const std::size_t k = t < r.time.front() ? 0 : r.sampleAt(t);
  if (k == shownSample_) return;
  shownSample_ = k;
  // Curves up to the playhead.
  const QVector<double> x(r.time.begin(), r.time.begin() + static_cast<std::ptrdiff_t>(k + 1));
  for (const Shown& s : shown_)
    s.graph->setData(x, QVector<double>(s.y.begin(), s.y.begin() + static_cast<std::ptrdiff_t>(k + 1)), true);

  // The decision table of Section 7.5.2, lit by the hypothesis tests of the moment.
  const TestTrace* h = r.trace(DiagnosisTest::Hypothesis);
  const DecisionStructure d = DecisionStructure::hypothesis(r.faults);
  std::vector<bool> fired(4, false);
  if (h)
    for (std::size_t c = 0; c < 4 && c < h->ratio.size(); ++c) fired[c] = h->ratio[c][k] > 1.0;
  const ModeSet s = d.diagnose(fired);
  const ModeSet decided = r.decision.statement[k];
  auto cell = [this](int row, int col, const QString& text, const QColor& bg) {
    auto* item = new QTableWidgetItem(text);
    item->setTextAlignment(Qt::AlignCenter);
    if (bg.isValid()) item->setBackground(bg);
    table_->setItem(row, col, item);
  };
  const int rows[] = {1, 2, 3, 0};  // table rows F_kT, F_Ja, F_fm, NF are modes 1, 2, 3, 0
  for (int row = 0; row < 4; ++row) {
    const std::size_t mode = static_cast<std::size_t>(rows[row]);
    const bool possible = decided & (ModeSet{1} << mode);
    for (int col = 0; col < 4; ++col) {
      const char mark = d.mark(mode, static_cast<std::size_t>(col));
      // A 0 under a fired column is what rejects the row's mode.
      const bool rejects = mark == '0' && fired[static_cast<std::size_t>(col)] && h;
      cell(row, col, QString(mark), rejects ? QColor(255, 200, 200) : QColor());
    }
    cell(row, 4, possible ? tr("possible") : tr("rejected"),
         possible ? (mode == 0 ? QColor(200, 235, 200) : QColor(255, 220, 160)) : QColor(235, 235, 235));
  }
  for (int col = 0; col < 4; ++col)
    cell(4, col, h ? (fired[static_cast<std::size_t>(col)] ? "1" : "0") : "-",
         h && fired[static_cast<std::size_t>(col)] ? QColor(255, 160, 160) : QColor(220, 240, 220));
  cell(4, 4, QString::fromStdString(modeSetString(s, r.faults)), QColor());

  // The verdict once the playhead has passed it; green until a fault is detected.
  QString verdict, color;
  QString parameter;
  const double now = r.time[k];
  if (r.modelCheck.mismatch && now >= *r.modelCheck.time - 1e-9) {
    verdict = tr("The model no longer fits (at %1): no parameter is named").arg(seconds(*r.modelCheck.time));
    verdict_->setToolTip(QString::fromStdString(r.modelCheck.message));
    color = "color: rgb(130,60,170)";
  } else if (r.decision.verdictTime && now >= *r.decision.verdictTime - 1e-9) {
    parameter = QString::fromStdString(r.verdictName());
    verdict = tr("Fault in %1 - isolated at %2").arg(parameter, seconds(*r.decision.verdictTime));
    color = "color: rgb(200,40,40)";
  } else if (r.decision.detectionTime && now >= *r.decision.detectionTime - 1e-9) {
    QStringList named;
    for (const auto& n : r.namedByTests()) named << QString::fromStdString(n);
    verdict = k + 1 < r.time.size() ? tr("Change detected at %1, not isolated yet").arg(seconds(*r.decision.detectionTime))
                                    : tr("Change detected at %1, not isolated to one parameter").arg(seconds(*r.decision.detectionTime));
    if (!named.isEmpty()) verdict += tr(" (the tests on their own name %1)").arg(named.join(", "));
    color = "color: rgb(220,140,0)";
  } else {
    verdict = k + 1 < r.time.size() ? tr("No fault so far (%1)").arg(seconds(now)) : tr("No fault: the axis is healthy");
    color = "color: rgb(40,140,60)";
  }
  verdict_->setText(verdict);
  verdict_->setStyleSheet(color);
  statement_->setText(tr("At %1: S = %2 (decision over %3); hypothesis pattern %4.")
                          .arg(seconds(now), QString::fromStdString(modeSetString(decided, r.faults)))
                          .arg(QString::number(static_cast<int>(r.decisionTests.size())) + tr(" tests"))
                          .arg(QString::fromStdString(patternString(fired))));
  if (parameter != shownVerdict_) {
    shownVerdict_ = parameter;
    emit verdictShown(parameter);
  }
  for (QCustomPlot* p : {estimates_, cusum_, hypothesis_, timeline_}) p->replot(QCustomPlot::rpQueuedReplot);
}

QString DiagnosisPanel::verdictText() const { return verdict_->text(); }
QString DiagnosisPanel::statementText() const { return statement_->text(); }
QString DiagnosisPanel::thresholdsText() const { return thresholds_->text(); }

}  // namespace flexarm
