#pragma once
// Step or impulse responses of several models against time (core/ident/transient.h), each
// with its shaded confidence band where the model has a covariance; legend above the data,
// the shared plot tools (zoom reset, export, data as CSV).
#include <QColor>
#include <QString>
#include <QWidget>

#include "core/ident/transient.h"

class QCustomPlot;

namespace flexarm {

class TransientPlot : public QWidget {
  Q_OBJECT
 public:
  explicit TransientPlot(QWidget* parent = nullptr);
  void clear();
  void setKind(TransientKind kind);
  void addCurve(const QString& name, const QColor& color, const TransientResponse& response);
  void rescale();
  int curveCount() const { return curves_; }
  QCustomPlot* customPlot() const { return plot_; }
  bool exportTo(const QString& path, QString* why = nullptr) const;

 private:
  QCustomPlot* plot_;
  int curves_ = 0;
};

}  // namespace flexarm
