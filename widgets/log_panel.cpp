#include "widgets/log_panel.h"

#include <QHBoxLayout>
#include <QKeyEvent>
#include <QHeaderView>
#include <QLabel>
#include <QLocale>
#include <QTableWidget>
#include <QToolButton>
#include <QVBoxLayout>
#include <algorithm>
#include <cmath>
#include <qcustomplot.h>

#include "widgets/playhead.h"
#include "widgets/plots/envelope_graph.h"
#include "widgets/plots/playhead_cursor.h"
#include "widgets/plots/plot_tools.h"

namespace flexarm {
namespace {

const QColor kEstimationColor(30, 110, 220);
const QColor kValidationColor(235, 130, 20);
const QColor kLoopColor(90, 160, 90);
const QColor kTraceColors[] = {QColor(31, 119, 180), QColor(214, 39, 40), QColor(44, 160, 44),
                               QColor(148, 103, 189), QColor(140, 86, 75), QColor(227, 119, 194),
                               QColor(127, 127, 127), QColor(188, 189, 34)};

QString label(const Channel& c) {
  QString s = QString::fromStdString(c.name);
  if (!c.unit.empty()) s += QString(" [%1]").arg(QString::fromStdString(c.unit));
  if (c.role != ChannelRole::None) s += QString("\n(%1)").arg(toString(c.role));
  return s;
}

}  // namespace

LogPanel::LogPanel(Workspace* workspace, QWidget* parent)
    : QWidget(parent), workspace_(workspace), plot_(new QCustomPlot(this)),
      readout_(new QLabel(this)), rangeTable_(new QTableWidget(2, 4, this)),
      playheadCursor_(new PlayheadCursor(plot_, this)), drawer_(new BackgroundRefresh(this)) {
  setObjectName("logPanel");
  auto* tools = new QHBoxLayout;
  auto makeButton = [&](const QString& text, const QString& tip, const QString& shortcut) {
    auto* b = new QToolButton(this);
    b->setText(text);
    b->setToolTip(tip + " (" + shortcut + ")");
    b->setCheckable(true);
    b->setAutoExclusive(true);
    b->setToolButtonStyle(Qt::ToolButtonTextOnly);
    tools->addWidget(b);
    return b;
  };
  navigateButton_ = makeButton(tr("Zoom / pan"), tr("Wheel zooms time, drag pans"), "Z");
  // Short names, the whole sentence in the tooltip: the panel stays narrow enough for a laptop.
  estimationButton_ = makeButton(tr("Estimation range"),
                                 tr("Select the estimation range: drag in the plot"), "E");
  validationButton_ = makeButton(tr("Validation range"),
                                 tr("Select the validation range: drag in the plot"), "V");
  loopButton_ = makeButton(tr("Loop"), tr("Select what the playhead loops over: drag in the plot"), "L");
  loopButton_->setObjectName("loopSelectButton");
  navigateButton_->setObjectName("navigateButton");
  estimationButton_->setObjectName("estimationButton");
  validationButton_->setObjectName("validationButton");
  navigateButton_->setChecked(true);
  auto* clear = new QToolButton(this);
  clear->setText(tr("Clear ranges"));
  clear->setObjectName("clearRangesButton");
  clear->setToolTip(tr("Remove the estimation and validation ranges (undo with Ctrl+Z)"));
  auto* all = new QToolButton(this);
  all->setText(tr("Show all"));
  all->setToolTip(tr("Show the whole log (double click in the plot does the same)"));
  tools->addSpacing(12);
  tools->addWidget(all);
  tools->addWidget(clear);
  tools->addStretch(1);

  readout_->setObjectName("readout");
  readout_->setTextInteractionFlags(Qt::TextSelectableByMouse);
  readout_->setText(tr("Open a log (Ctrl+O or drop a file here)"));
  QFont mono = readout_->font();
  mono.setFamily("monospace");
  mono.setStyleHint(QFont::Monospace);
  readout_->setFont(mono);
  // The readout's length follows the mouse: it never widens the panel (a range dragged in
  // the plot would land elsewhere than aimed as the plot changed width under the mouse).
  readout_->setSizePolicy(QSizePolicy::Ignored, QSizePolicy::Preferred);

  rangeTable_->setObjectName("rangeTable");
  rangeTable_->setHorizontalHeaderLabels({tr("Range"), tr("From [s]"), tr("To [s]"), tr("Samples")});
  rangeTable_->verticalHeader()->hide();
  rangeTable_->horizontalHeader()->setSectionResizeMode(QHeaderView::Stretch);
  // From and To can be typed (a double click or F2 on the cell): exact ranges such as 0.5-12 s.
  rangeTable_->setEditTriggers(QAbstractItemView::DoubleClicked | QAbstractItemView::EditKeyPressed);
  rangeTable_->setSelectionMode(QAbstractItemView::SingleSelection);
  rangeTable_->setToolTip(tr("Drag in the plot in range mode (E, V), or double click From or To "
                             "and type the time in seconds"));
  rangeTable_->setMaximumHeight(rangeTable_->horizontalHeader()->height() +
                                2 * rangeTable_->verticalHeader()->defaultSectionSize() + 6);

  plot_->setObjectName("logPlot");
  plot_->setNoAntialiasingOnDrag(true);
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  plot_->setMinimumHeight(240);
  plot_->setFocusPolicy(Qt::StrongFocus);  // a click gives the log view the E/V/Z/L keys

  auto* layout = new QVBoxLayout(this);
  layout->setContentsMargins(4, 4, 4, 4);
  layout->addLayout(tools);
  layout->addWidget(plot_, 1);
  layout->addWidget(readout_);
  layout->addWidget(rangeTable_);

  connect(navigateButton_, &QToolButton::toggled, this, [this](bool on) { if (on) setMode(Mode::Navigate); });
  connect(estimationButton_, &QToolButton::toggled, this, [this](bool on) { if (on) setMode(Mode::SelectEstimation); });
  connect(validationButton_, &QToolButton::toggled, this, [this](bool on) { if (on) setMode(Mode::SelectValidation); });
  connect(loopButton_, &QToolButton::toggled, this, [this](bool on) { if (on) setMode(Mode::SelectLoop); });
  connect(clear, &QToolButton::clicked, this, [this] {
    workspace_->clearRange(RangeKind::Estimation);
    workspace_->clearRange(RangeKind::Validation);
  });
  connect(all, &QToolButton::clicked, this, &LogPanel::showAll);
  connect(rangeTable_, &QTableWidget::itemChanged, this, &LogPanel::onRangeEdited);
  connect(plot_, &QCustomPlot::mousePress, this, &LogPanel::onMousePress);
  connect(plot_, &QCustomPlot::mouseMove, this, &LogPanel::onMouseMove);
  connect(plot_, &QCustomPlot::mouseRelease, this, &LogPanel::onMouseRelease);
  // Double click and the right-click menu reset the zoom to the whole log.
  PlotTools::install(plot_)->setReset([this] { showAll(); });
  connect(workspace_, &Workspace::currentChanged, this, &LogPanel::rebuild);
  connect(workspace_, &Workspace::rangesChanged, this, &LogPanel::updateRanges);
  playheadCursor_->setFollow(true);
  rebuild();
}

void LogPanel::setPlayhead(Playhead* playhead) {
  if (playhead_) disconnect(playhead_, nullptr, this, nullptr);
  playhead_ = playhead;
  playheadCursor_->setPlayhead(playhead);
  if (playhead_)
    connect(playhead_, &Playhead::selectionChanged, this, &LogPanel::updateLoopSelection);
  updateLoopSelection();
}

bool LogPanel::handleModeKey(QKeyEvent* e) {
  if (e->modifiers() & ~(Qt::KeypadModifier | Qt::ShiftModifier)) return false;
  switch (e->key()) {
    case Qt::Key_Z: setMode(Mode::Navigate); return true;
    case Qt::Key_E: setMode(Mode::SelectEstimation); return true;
    case Qt::Key_V: setMode(Mode::SelectValidation); return true;
    case Qt::Key_L: setMode(Mode::SelectLoop); return true;
    default: return false;
  }
}

void LogPanel::keyPressEvent(QKeyEvent* e) {
  if (handleModeKey(e))
    e->accept();
  else
    QWidget::keyPressEvent(e);
}

void LogPanel::setMode(Mode m) {
  mode_ = m;
  QToolButton* b = m == Mode::Navigate           ? navigateButton_
                   : m == Mode::SelectEstimation ? estimationButton_
                   : m == Mode::SelectValidation ? validationButton_
                                                 : loopButton_;
  if (!b->isChecked()) b->setChecked(true);
  plot_->setInteraction(QCP::iRangeDrag, m == Mode::Navigate);
  plot_->setCursor(m == Mode::Navigate ? Qt::OpenHandCursor : Qt::IBeamCursor);
}

QCPAxisRect* LogPanel::channelRect(int i) const {
  return i >= 0 && i < channelCount() ? rects_[static_cast<std::size_t>(i)] : nullptr;
}

double LogPanel::pixelForTime(double t) const {
  return rects_.empty() ? 0.0 : rects_.front()->axis(QCPAxis::atBottom)->coordToPixel(t);
}

double LogPanel::timeAtPixel(double x) const {
  return rects_.empty() ? 0.0 : rects_.front()->axis(QCPAxis::atBottom)->pixelToCoord(x);
}

QString LogPanel::readoutText() const { return readout_->text(); }

void LogPanel::rebuild() {
  plot_->clearItems();
  plot_->clearGraphs();
  plot_->plotLayout()->clear();
  rects_.clear();
  envelopes_.clear();
  cursors_.clear();
  estimationRects_.clear();
  validationRects_.clear();
  loopRects_.clear();
  const IdData* data = workspace_->shown();
  if (!plot_->layer("ranges")) {
    plot_->addLayer("ranges", plot_->layer("main"), QCustomPlot::limBelow);
    plot_->addLayer("cursor", plot_->layer("main"), QCustomPlot::limAbove);
  }
  plot_->layer("ranges")->setMode(QCPLayer::lmBuffered);
  overlay_ = plot_->layer("cursor");
  overlay_->setMode(QCPLayer::lmBuffered);
  if (!data || data->channels.empty()) {
    drawer_->cancel();
    plot_->replot();
    updateRanges();
    playheadCursor_->attach();
    return;
  }
  auto* margins = new QCPMarginGroup(plot_);
  const std::size_t n = data->samples();
  for (std::size_t c = 0; c < data->channels.size(); ++c) {
    const Channel& ch = data->channels[c];
    auto* rect = new QCPAxisRect(plot_);
    plot_->plotLayout()->addElement(static_cast<int>(c), 0, rect);
    rect->setMarginGroup(QCP::msLeft | QCP::msRight, margins);
    rect->setRangeDrag(Qt::Horizontal);
    rect->setRangeZoom(Qt::Horizontal);
    rect->setupFullAxesBox(false);
    QCPAxis* x = rect->axis(QCPAxis::atBottom);
    QCPAxis* y = rect->axis(QCPAxis::atLeft);
    y->setLabel(label(ch));
    const bool last = c + 1 == data->channels.size();
    x->setTickLabels(last);
    if (last) x->setLabel(tr("time [s]"));
    for (QCPAxis* a : rect->axes()) a->setLayer("axes");
    auto* g = plot_->addGraph(x, y);
    g->setPen(QPen(kTraceColors[c % 8], 1.2));
    double lo = HUGE_VAL, hi = -HUGE_VAL;  // NaN marks "not sampled here" in irregular logs
    for (double v : ch.values)
      if (!std::isnan(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    if (!(hi >= lo)) lo = hi = 0.0;
    const double pad = std::max(1e-12, 0.05 * (hi - lo));
    y->setRange(lo - pad, hi + pad);
    rects_.push_back(rect);
    // Panning and zooming stay inside the log: no time before its first sample.
    PlotTools::of(plot_)->limitAxis(x, [this]() -> std::pair<double, double> {
      const IdData* d = workspace_->shown();
      if (!d || d->samples() < 2) return {0.0, 0.0};
      return {d->startTime, d->timeAt(d->samples() - 1)};
    });
    connect(x, QOverload<const QCPRange&>::of(&QCPAxis::rangeChanged), this,
            [this, rect, c](const QCPRange&) {
              syncTimeAxes(rect);
              refreshChannel(c);
            });

    auto* cursor = new QCPItemStraightLine(plot_);
    cursor->setLayer(overlay_);
    cursor->setClipAxisRect(rect);
    for (auto* p : {cursor->point1, cursor->point2}) {
      p->setAxes(x, y);
      p->setAxisRect(rect);
      p->setTypeX(QCPItemPosition::ptPlotCoords);
      p->setTypeY(QCPItemPosition::ptAxisRectRatio);
    }
    cursor->point1->setCoords(data->startTime, 0);
    cursor->point2->setCoords(data->startTime, 1);
    cursor->setPen(QPen(QColor(60, 60, 60), 1, Qt::DashLine));
    cursor->setVisible(false);
    cursors_.push_back(cursor);

    for (auto [list, color] : {std::pair{&estimationRects_, kEstimationColor},
                               std::pair{&validationRects_, kValidationColor},
                               std::pair{&loopRects_, kLoopColor}}) {
      auto* r = new QCPItemRect(plot_);
      r->setLayer("ranges");
      r->setClipAxisRect(rect);
      for (auto* p : {r->topLeft, r->bottomRight}) {
        p->setAxes(x, y);
        p->setAxisRect(rect);
        p->setTypeX(QCPItemPosition::ptPlotCoords);
        p->setTypeY(QCPItemPosition::ptAxisRectRatio);
      }
      QColor fill = color;
      fill.setAlpha(55);
      r->setBrush(fill);
      r->setPen(QPen(color, 1));
      r->setVisible(false);
      list->push_back(r);
    }
  }
  showAll();
  updateRanges();
  updateLoopSelection();
  playheadCursor_->attach();
  // Millions of samples are drawn through a min/max envelope of the visible range, so zooming
  // and panning cost the same for a 10-minute log as for a short one; the envelopes are formed
  // in the background and the curves drawn when they are ready.
  const std::shared_ptr<const IdData> shared = workspace_->shownShared();
  drawer_->run([this, shared](const std::atomic<bool>& stop) -> BackgroundRefresh::Apply {
    auto formed = std::make_shared<std::vector<std::shared_ptr<const EnvelopePyramid>>>();
    for (const Channel& ch : shared->channels) {
      if (stop) return {};
      if (std::any_of(ch.values.begin(), ch.values.end(), [](double v) { return std::isnan(v); })) {
        // A channel logged at a lower rate than the rows: drawn through its own samples.
        std::vector<double> held = ch.values;
        double previous = 0.0;
        for (double v : held)
          if (!std::isnan(v)) {
            previous = v;
            break;
          }
        for (double& v : held) std::isnan(v) ? (v = previous) : (previous = v);
        formed->push_back(std::make_shared<const EnvelopePyramid>(held));
      } else {
        formed->push_back(std::make_shared<const EnvelopePyramid>(ch.values));
      }
    }
    return [this, shared, formed] {
      if (workspace_->shownShared() != shared || formed->size() != rects_.size()) return;
      envelopes_ = std::move(*formed);
      for (std::size_t c = 0; c < envelopes_.size(); ++c) refreshChannel(c);
      plot_->replot();
    };
  });
  readout_->setText(tr("%1 channels, %2 samples at %3 Hz, %4 s")
                        .arg(data->channels.size())
                        .arg(n)
                        .arg(data->sampleRateHz(), 0, 'g', 6)
                        .arg(data->duration(), 0, 'g', 6));
}

bool LogPanel::isBusy() const { return drawer_->isBusy(); }

void LogPanel::showAll() {
  const IdData* data = workspace_->shown();
  if (!data || rects_.empty()) return;
  for (auto* r : rects_)
    r->axis(QCPAxis::atBottom)->setRange(data->startTime, data->timeAt(data->samples() - 1));
  plot_->replot();
}

void LogPanel::showAround(double t) {
  const IdData* data = workspace_->shown();
  if (!data || rects_.empty()) return;
  const double half = std::max(25.0 * data->sampleTime, 0.01);
  for (auto* r : rects_) r->axis(QCPAxis::atBottom)->setRange(t - half, t + half);
  for (auto* c : cursors_) {
    c->point1->setCoords(t, 0);
    c->point2->setCoords(t, 1);
    c->setVisible(true);
  }
  plot_->replot();
}

void LogPanel::syncTimeAxes(QCPAxisRect* source) {
  if (syncing_) return;
  syncing_ = true;
  const QCPRange r = source->axis(QCPAxis::atBottom)->range();
  for (auto* rect : rects_)
    if (rect != source) rect->axis(QCPAxis::atBottom)->setRange(r);
  syncing_ = false;
}

void LogPanel::refreshChannel(std::size_t c) {
  const IdData* data = workspace_->shown();
  if (!data || c >= rects_.size() || c >= envelopes_.size()) return;
  const QCPRange r = rects_[c]->axis(QCPAxis::atBottom)->range();
  const std::size_t n = data->samples();
  const std::size_t first = data->indexNear(r.lower) > 1 ? data->indexNear(r.lower) - 2 : 0;
  const std::size_t last = std::min(n, data->indexNear(r.upper) + 3);
  static thread_local std::vector<double> position, value;
  envelopes_[c]->visiblePoints(first, last, envelopePointBudget(rects_[c]->width()), position, value);
  setDenseDrawing(plot_->graph(static_cast<int>(c)), position.size() >= static_cast<std::size_t>(rects_[c]->width()));
  QVector<QCPGraphData> points(static_cast<int>(position.size()));
  for (std::size_t i = 0; i < position.size(); ++i)  // positions are sample indices
    points[static_cast<int>(i)] = QCPGraphData(data->timeAt(static_cast<std::size_t>(position[i])), value[i]);
  plot_->graph(static_cast<int>(c))->data()->set(points, true);
}

void LogPanel::placeRect(QCPItemRect* item, double t0, double t1, bool visible) {
  item->topLeft->setCoords(std::min(t0, t1), 0);
  item->bottomRight->setCoords(std::max(t0, t1), 1);
  item->setVisible(visible);
}

QString LogPanel::secondsText(double t) const {
  // To a tenth of the log's sample time: a .mat log's 0.5119999871 reads 0.512.
  const IdData* data = workspace_->current();
  const double ts = data && data->sampleTime > 0.0 ? data->sampleTime : 1e-9;
  const int decimals = std::clamp(static_cast<int>(std::ceil(-std::log10(ts / 10.0))), 0, 9);
  QString text = QString::number(t, 'f', decimals);
  if (text.contains('.')) {
    while (text.endsWith('0')) text.chop(1);
    if (text.endsWith('.')) text.chop(1);
  }
  return text;
}

void LogPanel::updateRanges() {
  struct Row {
    RangeKind kind;
    std::vector<QCPItemRect*>* rects;
    QColor color;
  };
  const Row rows[] = {{RangeKind::Estimation, &estimationRects_, kEstimationColor},
                      {RangeKind::Validation, &validationRects_, kValidationColor}};
  for (int i = 0; i < 2; ++i) {
    const Row& row = rows[i];
    const auto r = workspace_->range(row.kind);
    for (auto* item : *row.rects) placeRect(item, r ? r->start : 0, r ? r->end : 0, r.has_value());
    const SampleRange s = workspace_->samples(row.kind);
    QStringList cells = {row.kind == RangeKind::Estimation ? tr("Estimation") : tr("Validation"),
                         r ? secondsText(r->start) : QString("-"), r ? secondsText(r->end) : QString("-"),
                         r ? QString::number(s.size()) : tr("drag in the plot")};
    const QSignalBlocker block(rangeTable_);  // filling is no edit
    for (int c = 0; c < 4; ++c) {
      QTableWidgetItem* item = rangeTable_->item(i, c);
      if (!item) {  // made once: an edit in progress keeps its item
        item = new QTableWidgetItem;
        if (c == 0) item->setForeground(row.color.darker(120));
        if (c == 1 || c == 2)
          item->setToolTip(tr("Double click to type the time in seconds"));
        else
          item->setFlags(item->flags() & ~Qt::ItemIsEditable);
        rangeTable_->setItem(i, c, item);
      }
      item->setText(cells[c]);
    }
  }
  if (auto* layer = plot_->layer("ranges")) layer->replot();
  plot_->replot(QCustomPlot::rpQueuedReplot);
}

bool LogPanel::setRangeText(RangeKind kind, const QString& from, const QString& to, QString* why) {
  const IdData* data = workspace_->current();
  auto fail = [why](const QString& reason) {
    if (why) *why = reason;
    return false;
  };
  if (!data || data->samples() < 2) return fail(tr("open a log first"));
  const double first = data->startTime, last = data->timeAt(data->samples() - 1);
  auto parse = [](QString text, double fallback, bool* ok) {
    text = text.trimmed();
    if (text.endsWith('s')) text.chop(1);
    text = text.trimmed();
    if (text.isEmpty() || text == "-") {
      *ok = true;
      return fallback;
    }
    return QLocale::c().toDouble(text, ok);
  };
  bool ok0 = false, ok1 = false;
  const double t0 = parse(from, first, &ok0), t1 = parse(to, last, &ok1);
  if (!ok0) return fail(tr("'%1' is not a time in seconds").arg(from));
  if (!ok1) return fail(tr("'%1' is not a time in seconds").arg(to));
  if (!(t1 > t0)) return fail(tr("the range must end after it starts (%1 to %2 s)").arg(t0).arg(t1));
  if (t0 < first - 0.5 * data->sampleTime || t1 > last + 0.5 * data->sampleTime)
    return fail(tr("%1 to %2 s is outside the log (%3 to %4 s)").arg(t0).arg(t1).arg(first).arg(last));
  if (data->rangeForTimes(t0, t1).size() < 2) return fail(tr("the range holds fewer than 2 samples"));
  workspace_->setRange(kind, {std::max(t0, first), std::min(t1, last)});
  return true;
}

void LogPanel::onRangeEdited(QTableWidgetItem* item) {
  if (!item || item->row() < 0 || item->row() > 1 || (item->column() != 1 && item->column() != 2))
    return;
  const RangeKind kind = item->row() == 0 ? RangeKind::Estimation : RangeKind::Validation;
  const auto old = workspace_->range(kind);
  const QString from = item->column() == 1 ? item->text()
                       : old             ? QString::number(old->start, 'g', 17)
                                         : QString();
  const QString to = item->column() == 2 ? item->text()
                     : old               ? QString::number(old->end, 'g', 17)
                                         : QString();
  QString why;
  if (!setRangeText(kind, from, to, &why)) {
    updateRanges();  // back to the range in force
    readout_->setText(tr("Range not changed: %1").arg(why));
  }
}

void LogPanel::updateLoopSelection() {
  const auto s = playhead_ ? playhead_->selection() : std::nullopt;
  for (auto* item : loopRects_) placeRect(item, s ? s->first : 0, s ? s->second : 0, s.has_value());
  if (auto* layer = plot_->layer("ranges")) layer->replot();
}

void LogPanel::onMousePress(QMouseEvent* e) {
  if (mode_ == Mode::Navigate || rects_.empty() || e->button() != Qt::LeftButton) return;
  selecting_ = true;
  selectStart_ = timeAtPixel(e->position().x());
}

void LogPanel::onMouseMove(QMouseEvent* e) {
  const IdData* data = workspace_->shown();
  if (!data || rects_.empty()) return;
  const double t = timeAtPixel(e->position().x());
  for (auto* c : cursors_) {
    c->point1->setCoords(t, 0);
    c->point2->setCoords(t, 1);
    c->setVisible(true);
  }
  if (data->samples() > 0 && t >= data->timeAt(0) - 0.5 * data->sampleTime &&
      t <= data->timeAt(data->samples() - 1) + 0.5 * data->sampleTime) {
    const std::size_t i = data->indexNear(t);
    QString text = QString("t = %1 s").arg(data->timeAt(i), 0, 'f', 4);
    for (const auto& ch : data->channels)
      text += QString("   %1 = %2").arg(QString::fromStdString(ch.name)).arg(ch.values[i], 0, 'g', 6);
    readout_->setText(text);
  }
  if (selecting_) {
    auto* list = mode_ == Mode::SelectEstimation   ? &estimationRects_
                 : mode_ == Mode::SelectValidation ? &validationRects_
                                                   : &loopRects_;
    for (auto* item : *list) placeRect(item, selectStart_, t, true);
    plot_->layer("ranges")->replot();
  }
  overlay_->replot();
}

void LogPanel::onMouseRelease(QMouseEvent* e) {
  if (!selecting_) return;
  selecting_ = false;
  const IdData* data = workspace_->shown();
  double t0 = selectStart_, t1 = timeAtPixel(e->position().x());
  if (t1 < t0) std::swap(t0, t1);
  t0 = std::max(t0, data->startTime);
  t1 = std::min(t1, data->timeAt(data->samples() - 1));
  if (t1 - t0 < 2.0 * data->sampleTime) {  // a click, not a drag: keep the old range
    updateRanges();
    updateLoopSelection();
    return;
  }
  if (mode_ == Mode::SelectLoop) {
    if (playhead_) playhead_->setSelection(t0, t1);
    updateLoopSelection();
    return;
  }
  const RangeKind kind = mode_ == Mode::SelectEstimation ? RangeKind::Estimation : RangeKind::Validation;
  // Snap to samples so the listed times are sample times.
  const SampleRange s = data->rangeForTimes(t0, t1);
  workspace_->setRange(kind, {data->timeAt(s.begin), data->timeAt(s.end - 1)});
}


}  // namespace flexarm
