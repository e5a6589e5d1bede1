#pragma once
// What the Arm view writes over its 3D picture: where the angles come from and the scales
// (top left), the time and the deflections (bottom left), and the legend of the springs'
// colour scale (right). Painted with QPainter by the view's overlay callback.
#include <QColor>
#include <QString>
#include <functional>

class QPainter;
class QRect;

namespace flexarm {

struct ArmOverlay {
  QString caption;
  QString status;
  bool legend = false;          // the springs are coloured by their deflection
  double maxDeflection = 0.0;   // the colour scale spans +-maxDeflection, rad
  std::function<QColor(double deflection)> colour;
  bool visible = true;
};

void paintArmOverlay(QPainter& painter, const QRect& area, const ArmOverlay& overlay);

}  // namespace flexarm
