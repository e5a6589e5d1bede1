#pragma once
// The mouse wheel scrolls what is under it unless a control has the focus: a spin box, combo
// box or slider the wheel passes over while a panel is scrolled keeps its value (a decimation
// factor does not go from 10 to 7 on the way down). Such a control takes the focus by a click
// or Tab, never by the wheel, and then the wheel steps it as usual. Installed once for the
// whole application (WheelGuard::install); every control of every panel, present or added
// later, is covered.
#include <QObject>

class QWidget;

namespace flexarm {

class WheelGuard : public QObject {
  Q_OBJECT
 public:
  // Installs the guard on the application (once; later calls do nothing).
  static void install();
  // True when w is a control the guard keeps from an unfocused wheel.
  static bool guards(const QWidget* w);

 protected:
  bool eventFilter(QObject* watched, QEvent* event) override;

 private:
  using QObject::QObject;
};

}  // namespace flexarm
