#include "widgets/timing_table.h"

#include <QHeaderView>
#include <algorithm>

namespace flexarm {
namespace {

QString kindText(TimingEventKind k) {
  switch (k) {
    case TimingEventKind::Jitter: return QObject::tr("jitter");
    case TimingEventKind::Gap: return QObject::tr("gap");
    case TimingEventKind::Duplicate: return QObject::tr("duplicate");
    case TimingEventKind::Reversal: return QObject::tr("reversal");
  }
  return {};
}

QString detailText(const TimingEvent& e) {
  switch (e.kind) {
    case TimingEventKind::Jitter:
      return QObject::tr("%1 % off its grid point").arg(100.0 * e.size, 0, 'f', 1);
    case TimingEventKind::Gap:
      return e.missing == 1 ? QObject::tr("%1 ms, 1 sample missing").arg(1e3 * e.size, 0, 'g', 4)
                            : QObject::tr("%1 ms, %2 samples missing").arg(1e3 * e.size, 0, 'g', 4).arg(e.missing);
    case TimingEventKind::Duplicate: return QObject::tr("same time as the line before");
    case TimingEventKind::Reversal: return QObject::tr("%1 ms back in time").arg(1e3 * e.size, 0, 'g', 4);
  }
  return {};
}

}  // namespace

TimingTable::TimingTable(QWidget* parent) : QTableWidget(0, 4, parent) {
  setObjectName("timingTable");
  setHorizontalHeaderLabels({tr("Event"), tr("Time [s]"), tr("Line"), tr("Detail")});
  verticalHeader()->hide();
  verticalHeader()->setDefaultSectionSize(fontMetrics().height() + 6);
  horizontalHeader()->setSectionResizeMode(QHeaderView::ResizeToContents);
  horizontalHeader()->setStretchLastSection(true);
  setEditTriggers(QAbstractItemView::NoEditTriggers);
  setSelectionBehavior(QAbstractItemView::SelectRows);
  setSelectionMode(QAbstractItemView::SingleSelection);
  setToolTip(tr("Click a row to show the place in the Log panel"));
  connect(this, &QTableWidget::currentCellChanged, this, [this](int row, int, int, int) {
    if (row >= 0) emit timeSelected(timeOfRow(row));
  });
  connect(this, &QTableWidget::cellClicked, this, [this](int row, int) { emit timeSelected(timeOfRow(row)); });
}

void TimingTable::setReports(const std::vector<TimingReport>& reports, int maxRows) {
  std::vector<const TimingEvent*> events;
  for (const auto& r : reports)
    for (const auto& e : r.events) events.push_back(&e);
  std::stable_sort(events.begin(), events.end(),
                   [](const TimingEvent* a, const TimingEvent* b) { return a->time < b->time; });
  const int rows = static_cast<int>(std::min<std::size_t>(events.size(), static_cast<std::size_t>(maxRows)));
  QSignalBlocker block(this);
  clearContents();
  setRowCount(rows);
  for (int i = 0; i < rows; ++i) {
    const TimingEvent& e = *events[static_cast<std::size_t>(i)];
    auto* time = new QTableWidgetItem(QString::number(e.time, 'f', 6));
    time->setData(Qt::UserRole, e.time);
    const QString line = e.line > 0 ? QString::number(e.line) : tr("sample %1").arg(e.index);
    const QString cells[] = {kindText(e.kind), QString(), line, detailText(e)};
    for (int c = 0; c < 4; ++c) setItem(i, c, c == 1 ? time : new QTableWidgetItem(cells[c]));
  }
}

double TimingTable::timeOfRow(int row) const {
  const QTableWidgetItem* it = item(row, 1);
  return it ? it->data(Qt::UserRole).toDouble() : 0.0;
}

}  // namespace flexarm
