#pragma once
// Bode plot: magnitude and phase against frequency (rad/s, log axis) for several curves,
// each optionally with a shaded confidence band or drawn as points (non-parametric
// estimates). Clicking near a curve reads the nearest peak or notch; clicking a legend entry
// hides or shows its curve; the plot exports to PNG, PDF or SVG.
#include <QColor>
#include <QString>
#include <QWidget>
#include <complex>
#include <optional>
#include <vector>

class QCustomPlot;
class QCPAxisRect;
class QCPGraph;
class QLabel;

namespace flexarm {

struct BodeCurve {
  QString name;
  QColor color;
  std::vector<double> frequency;  // rad/s, increasing
  std::vector<std::complex<double>> response;
  // Optional band: magnitude limits (absolute) and phase limits (degrees), same length.
  std::vector<double> magnitudeLow, magnitudeHigh, phaseLowDeg, phaseHighDeg;
  bool points = false;  // scatter instead of a line
};

class BodePlot : public QWidget {
  Q_OBJECT
 public:
  explicit BodePlot(QWidget* parent = nullptr);

  void clear();
  // Adds a curve and returns its index.
  int addCurve(const BodeCurve& curve);
  int curveCount() const { return static_cast<int>(curves_.size()); }
  void setCurveVisible(int index, bool visible);
  bool isCurveVisible(int index) const;
  // Rescales both axes to the visible curves.
  void rescale();

  // Finds the peak or notch of curve `index` nearest to frequency w: the local maximum or
  // minimum of the magnitude within a factor 1.5 of w. Returns its frequency and level (dB).
  std::optional<std::pair<double, double>> extremumNear(int index, double w) const;
  QString readoutText() const;
  QCustomPlot* plot() const { return plot_; }
  QCPAxisRect* magnitudeRect() const { return magRect_; }

  // Writes the plot as PNG, PDF or SVG (by extension); false with a reason otherwise.
  bool exportTo(const QString& path, QString* why = nullptr) const;

 signals:
  void extremumPicked(int curve, double frequency, double levelDb);

 private:
  struct Entry {
    BodeCurve curve;
    std::vector<double> magnitudeDb, phaseDeg;
    QCPGraph* mag = nullptr;
    QCPGraph* phase = nullptr;
    std::vector<QCPGraph*> band;  // low/high pairs filled between
  };
  void onClick(QMouseEvent* e);

  QCustomPlot* plot_;
  QCPAxisRect* magRect_;
  QCPAxisRect* phaseRect_;
  QLabel* readout_;
  std::vector<Entry> curves_;
};

// Unwrapped phase in degrees of a frequency response.
std::vector<double> unwrappedPhaseDeg(const std::vector<std::complex<double>>& response);

}  // namespace flexarm
