#pragma once
// Helpers shared by the widget tests: the VTK surface format, screenshots, pixel checks.
#include <QApplication>
#include <QDir>
#include <QImage>
#include <QMessageBox>
#include <QMouseEvent>
#include <QString>
#include <QTest>
#include <QWidget>

#include "widgets/arm/vtk_view.h"

namespace flexarm::test {

// main() of a widget test: the VTK surface format before the application, the settings under
// organisation org (each test its own: no layout or recent files left by another), then the
// test object's slots.
template <class Test>
int runWidgetTest(int argc, char** argv, const char* org) {
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName(org);
  Test t;
  return QTest::qExec(&t, argc, argv);
}

// Saves a screenshot under the build tree's screenshots/ folder and returns its path.
inline QString saveShot(const QImage& image, const QString& name) {
  QDir().mkpath(FLEXARM_SCREENSHOT_DIR);
  const QString path = QString(FLEXARM_SCREENSHOT_DIR) + "/" + name + ".png";
  image.save(path);
  return path;
}

// The visible message box with this object name, or null.
inline QMessageBox* findBox(const char* name) {
  for (QWidget* w : QApplication::topLevelWidgets())
    if (auto* box = qobject_cast<QMessageBox*>(w); box && box->objectName() == name && box->isVisible())
      return box;
  return nullptr;
}

// A mouse move delivered straight to the widget (with the buttons held), so no other window
// can take it.
inline void moveMouse(QWidget* w, QPoint p, Qt::MouseButtons held = Qt::NoButton) {
  QMouseEvent move(QEvent::MouseMove, QPointF(p), w->mapToGlobal(QPointF(p)), Qt::NoButton, held,
                   Qt::NoModifier);
  QApplication::sendEvent(w, &move);
}

// Fraction of pixels that look like the arm's orange paint (RGB 237,115,26 before lighting).
inline double orangeFraction(const QImage& image) {
  const QImage img = image.convertToFormat(QImage::Format_RGB32);
  qint64 hits = 0;
  for (int y = 0; y < img.height(); ++y)
    for (int x = 0; x < img.width(); ++x) {
      const QColor c = img.pixelColor(x, y);
      if (c.red() > 90 && c.red() > 1.4 * c.green() && c.green() > c.blue() + 15) ++hits;
    }
  return img.isNull() ? 0.0 : static_cast<double>(hits) / (img.width() * img.height());
}

// Number of pixels whose colour differs between two images of the same size.
inline qint64 differingPixels(const QImage& a, const QImage& b) {
  if (a.size() != b.size()) return -1;
  const QImage x = a.convertToFormat(QImage::Format_RGB32);
  const QImage y = b.convertToFormat(QImage::Format_RGB32);
  qint64 n = 0;
  for (int r = 0; r < x.height(); ++r)
    for (int c = 0; c < x.width(); ++c)
      if (x.pixel(c, r) != y.pixel(c, r)) ++n;
  return n;
}

}  // namespace flexarm::test
