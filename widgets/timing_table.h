#pragma once
// The time-stamp report of a log as a table: every jitter, gap, duplicate and reversal with
// its time, file line and size. Clicking a row (or moving to it with the keys) emits its time,
// so that the Log panel can show the place.
#include <QTableWidget>
#include <vector>

#include "core/signal/timing.h"

namespace flexarm {

class TimingTable : public QTableWidget {
  Q_OBJECT
 public:
  explicit TimingTable(QWidget* parent = nullptr);
  // Lists the events of the reports (one per group of channels sharing their instants), in
  // time order, at most maxRows of them; empty reports clear the table.
  void setReports(const std::vector<TimingReport>& reports, int maxRows = 2000);
  double timeOfRow(int row) const;

 signals:
  void timeSelected(double seconds);
};

}  // namespace flexarm
