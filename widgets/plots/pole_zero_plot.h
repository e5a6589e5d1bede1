#pragma once
// Pole-zero map of a continuous-time system: poles as crosses, zeros as circles, in the
// complex plane (rad/s), with the imaginary axis marked. Several sets can be overlaid, and an
// estimate's confidence regions (core/ident/pole_zero_regions.h) drawn around its points.
#include <QColor>
#include <QString>
#include <QWidget>
#include <complex>
#include <vector>

class QCustomPlot;

namespace flexarm {

class PoleZeroPlot : public QWidget {
  Q_OBJECT
 public:
  explicit PoleZeroPlot(QWidget* parent = nullptr);
  void clear();
  void addSet(const QString& name, const QColor& color,
              const std::vector<std::complex<double>>& poles,
              const std::vector<std::complex<double>>& zeros);
  // Closed boundaries of confidence regions, drawn as outlines in color; one legend entry.
  void addRegions(const QString& label, const QColor& color,
                  const std::vector<std::vector<std::complex<double>>>& boundaries);
  int regionCount() const { return regions_; }
  // Fits the view to every point (with the origin).
  void rescale();
  QCustomPlot* plot() const { return plot_; }
  int pointCount() const;

 private:
  QCustomPlot* plot_;
  int regions_ = 0;
};

}  // namespace flexarm
