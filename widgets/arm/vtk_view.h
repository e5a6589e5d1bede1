#pragma once
// A Qt 6 widget that shows a VTK renderer (VTK's own Qt module is built for Qt 5 on Debian,
// see shared/notes/platform.md). VTK renders into its own framebuffers in an OpenGL context
// this widget owns on an offscreen surface; the picture is read back from VTK's display
// framebuffer and painted as an image. The window therefore stays a plain raster window: with a QOpenGLWidget inside, Qt
// composites the whole window through OpenGL on every repaint of any widget, which on a
// software renderer (Mesa llvmpipe, as under Xvfb) costs more than the 3D scene itself.
// The scene renders only when requestRender() was called (or the size changed); other
// repaints show the last picture. Texts and legends are painted over it by an overlay
// callback with QPainter (Qt caches its glyphs; VTK's text actors rasterise a changed string
// afresh every frame). The camera follows the mouse: left drag rotates, right drag
// or wheel zooms, middle drag (or shift + left) pans, double click resets.
#include <QImage>
#include <QPoint>
#include <QWidget>
#include <functional>
#include <memory>
#include <vector>
#include <vtkSmartPointer.h>

class QOffscreenSurface;
class QPainter;
class QOpenGLContext;
class vtkGenericOpenGLRenderWindow;
class vtkRenderer;

namespace flexarm {

class VtkView : public QWidget {
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
  // Paints over the rendered scene (in widget coordinates), on screen and in grabbed images.
  using Overlay = std::function<void(QPainter& painter, const QRect& area)>;
  void setOverlay(Overlay overlay) { overlay_ = std::move(overlay); }
  // The scene changed: render it at the next repaint. The overlay changed: repaint only.
  void requestRender();
  void requestOverlay() { update(); }
  // The view as shown (scene and overlay), rendered now if the scene changed (the widget's
  // size, device pixels).
  QImage grabFramebuffer();

  // Camera moves, also used by tests.
  void rotateBy(double azimuthDeg, double elevationDeg);
  void zoomBy(double factor);

  // Frames rendered and the time spent rendering them (render and read back) since the last
  // reset, to measure the frame rate and to check that nothing renders when nothing changed.
  struct FrameStats {
    qint64 frames = 0;
    double renderSeconds = 0.0;
    double worstSeconds = 0.0;
  };
  FrameStats frameStats() const { return stats_; }
  void resetFrameStats() { stats_ = {}; }

 protected:
  void paintEvent(QPaintEvent* e) override;
  void resizeEvent(QResizeEvent* e) override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void mouseDoubleClickEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;

 private:
  bool makeCurrent();
  void render();
  void renderIfNeeded();
  void pan(QPoint delta);

  vtkSmartPointer<vtkGenericOpenGLRenderWindow> window_;
  vtkSmartPointer<vtkRenderer> renderer_;
  std::unique_ptr<QOpenGLContext> context_;
  std::unique_ptr<QOffscreenSurface> surface_;
  std::vector<unsigned char> pixels_;  // read back, bottom row first
  bool initialized_ = false;
  bool failed_ = false;
  bool dirty_ = true;
  QImage image_;
  std::function<void()> reset_;
  Overlay overlay_;
  QPoint last_;
  Qt::MouseButton dragging_ = Qt::NoButton;
  bool panning_ = false;
  FrameStats stats_;
};

}  // namespace flexarm
