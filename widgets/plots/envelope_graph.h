#pragma once
// A long uniformly sampled curve in a QCustomPlot graph, drawn through its min/max envelope
// (core/signal/envelope.h): the graph holds only the points of its visible time range, at
// most about two per pixel column, recomputed whenever the time axis moves. Zooming and
// panning cost the same for a 10-minute log as for a short one.
#include <QObject>
#include <memory>

#include "core/signal/envelope.h"

class QCPGraph;

namespace flexarm {

class EnvelopeGraph : public QObject {
  Q_OBJECT
 public:
  // Sample i of the envelope is at time startTime + i * sampleTime. The graph owns this
  // object (it goes with the graph).
  EnvelopeGraph(QCPGraph* graph, std::shared_ptr<const EnvelopePyramid> envelope,
                double startTime, double sampleTime);

  // Gives the graph the points of its visible time range.
  void refresh();

 private:
  QCPGraph* graph_;
  std::shared_ptr<const EnvelopePyramid> envelope_;
  double startTime_, sampleTime_;
};

// Draws a graph holding about a point per pixel column or more without antialiasing (which
// then only costs time), a sparser one with it.
void setDenseDrawing(QCPGraph* graph, bool dense);

// Points per visible range for a plot `pixels` wide: two per column, at least 1600.
std::size_t envelopePointBudget(int pixels);

}  // namespace flexarm
