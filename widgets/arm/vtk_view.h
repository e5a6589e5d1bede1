#pragma once
// A Qt 6 QOpenGLWidget that hosts a VTK renderer (VTK's own Qt module is built for Qt 5 on
// Debian, see shared/notes/platform.md). The camera follows the mouse: left drag rotates,
// right drag or wheel zooms, middle drag (or shift + left) pans, double click resets.
#include <QOpenGLWidget>
#include <QPoint>
#include <functional>
#include <vtkSmartPointer.h>

class vtkGenericOpenGLRenderWindow;
class vtkRenderer;

namespace flexarm {

class VtkView : public QOpenGLWidget {
  Q_OBJECT
 public:
  explicit VtkView(QWidget* parent = nullptr);
  // Makes the 3.2 core profile VTK needs the default; call before QApplication exists.
  static void installDefaultSurfaceFormat();
  ~VtkView() override;

  void setRenderer(vtkRenderer* renderer);
  vtkRenderer* renderer() const;
  // Called on double click to put the camera back.
  void setResetCamera(std::function<void()> reset) { reset_ = std::move(reset); }

  // Camera moves, also used by tests.
  void rotateBy(double azimuthDeg, double elevationDeg);
  void zoomBy(double factor);

 protected:
  void initializeGL() override;
  void resizeGL(int w, int h) override;
  void paintGL() override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void mouseDoubleClickEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;

 private:
  void pan(QPoint delta);

  vtkSmartPointer<vtkGenericOpenGLRenderWindow> window_;
  vtkSmartPointer<vtkRenderer> renderer_;
  std::function<void()> reset_;
  QPoint last_;
  Qt::MouseButton dragging_ = Qt::NoButton;
  bool panning_ = false;
};

}  // namespace flexarm
