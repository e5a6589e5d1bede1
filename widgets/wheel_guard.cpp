#include "widgets/wheel_guard.h"

#include <QAbstractSlider>
#include <QAbstractSpinBox>
#include <QApplication>
#include <QComboBox>
#include <QEvent>
#include <QScrollBar>
#include <QWheelEvent>

namespace flexarm {

void WheelGuard::install() {
  if (!qApp || qApp->property("flexarmWheelGuard").toBool()) return;
  qApp->setProperty("flexarmWheelGuard", true);
  qApp->installEventFilter(new WheelGuard(qApp));
}

bool WheelGuard::guards(const QWidget* w) {
  if (!w || qobject_cast<const QScrollBar*>(w)) return false;  // a scroll bar is what scrolls
  return qobject_cast<const QAbstractSpinBox*>(w) || qobject_cast<const QComboBox*>(w) ||
         qobject_cast<const QAbstractSlider*>(w);
}

bool WheelGuard::eventFilter(QObject* watched, QEvent* event) {
  if (!watched->isWidgetType()) return false;
  auto* w = static_cast<QWidget*>(watched);
  // Before a control is first shown: the focus comes by a click or Tab, not by the wheel.
  if (event->type() == QEvent::Polish && guards(w) && (w->focusPolicy() & Qt::WheelFocus) == Qt::WheelFocus)
    w->setFocusPolicy(Qt::StrongFocus);
  if (event->type() != QEvent::Wheel || !guards(w) || w->hasFocus()) return false;
  // Unused here, the event goes on to the parents: the scroll area around the panel scrolls.
  event->ignore();
  return true;
}

}  // namespace flexarm
