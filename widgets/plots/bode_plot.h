#pragma once
// Bode plot: magnitude and phase against frequency (rad/s, log axis) for several curves,
// each optionally with a shaded confidence band or drawn as points (non-parametric
// estimates). Clicking near a curve reads the nearest peak or notch; clicking a legend entry
// hides or shows its curve; the plot exports to PNG, PDF or SVG.
#include <QColor>
#include <QSet>
#include <QString>
#include <QWidget>
#include <complex>
#include <functional>
#include <optional>
#include <vector>

class QCustomPlot;
class QCPAxisRect;
class QCPGraph;
class QLabel;

namespace flexarm {

struct NotchesPeaks;

struct BodeCurve {
  QString name;
  QColor color;
  std::vector<double> frequency;  // rad/s, increasing
  std::vector<std::complex<double>> response;
  // Optional band: magnitude limits (absolute) and phase limits (degrees), same length.
  std::vector<double> magnitudeLow, magnitudeHigh, phaseLowDeg, phaseHighDeg;
  bool points = false;  // scatter instead of a line
  // The curve's notches and peaks by the core definition (magnitudeExtrema,
  // core/models/analysis.h), level in dB. With extremaKnown the click snaps to these (the
  // Bode panel gives a model the values of notchesAndPeaks, exactly what the Model panel
  // prints); otherwise addCurve finds them on the samples themselves.
  struct Extremum {
    double frequency = 0.0;  // rad/s
    double levelDb = 0.0;
    bool peak = false;
  };
  std::vector<Extremum> extrema;
  bool extremaKnown = false;
};

class BodePlot : public QWidget {
  Q_OBJECT
 public:
  explicit BodePlot(QWidget* parent = nullptr);

  void clear();
  // Adds a curve and returns its index.
  int addCurve(const BodeCurve& curve);
  int curveCount() const { return static_cast<int>(curves_.size()); }
  // Hides or shows a curve and rescales to what is shown. The choice is kept by the curve's
  // name: a curve drawn again under that name (after clear()) comes back hidden.
  void setCurveVisible(int index, bool visible);
  bool isCurveVisible(int index) const;
  // Rescales both axes to the visible curves, their bands widening the magnitude and phase
  // axes only where the bands stay near the curves (never to a notch's -6000 dB).
  void rescale();

  // The peak or notch of curve `index` (BodeCurve::extrema) nearest to frequency w, within a
  // factor 1.5 of it.
  std::optional<BodeCurve::Extremum> extremumNear(int index, double w) const;
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
  QSet<QString> hidden_;  // names of the curves the user hid
};

// Notches and peaks of a sampled response by magnitudeExtrema (core/models/analysis.h), the
// level interpolated on the samples: what a click reads on a curve given without extrema.
std::vector<BodeCurve::Extremum> sampledExtrema(const std::vector<double>& omega,
                                               const std::vector<std::complex<double>>& response);

// A model's notches and peaks (notchesAndPeaks, core/models/analysis.h) as curve extrema, the
// level from |G| at each frequency.
std::vector<BodeCurve::Extremum> curveExtrema(const NotchesPeaks& np,
                                              const std::function<double(double)>& magnitudeAt);

// Unwrapped phase in degrees of a frequency response.
std::vector<double> unwrappedPhaseDeg(const std::vector<std::complex<double>>& response);

}  // namespace flexarm
