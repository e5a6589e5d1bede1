#include "widgets/arm/vtk_view.h"

#include <QMouseEvent>
#include <QSurfaceFormat>
#include <QWheelEvent>
#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkRenderer.h>

#include <algorithm>
#include <cmath>

namespace flexarm {

VtkView::VtkView(QWidget* parent)
    : QOpenGLWidget(parent), window_(vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New()) {
  window_->SetOwnContext(false);
  window_->SetFrameBlitModeToBlitToCurrent();
  window_->SetMultiSamples(0);
  setMinimumSize(200, 160);
  setFocusPolicy(Qt::StrongFocus);
  setToolTip(tr("Drag to rotate, wheel or right drag to zoom, middle drag to pan, "
                "double click to reset the view"));
}

void VtkView::installDefaultSurfaceFormat() {
  QSurfaceFormat format;
  format.setRenderableType(QSurfaceFormat::OpenGL);
  format.setVersion(3, 2);
  format.setProfile(QSurfaceFormat::CoreProfile);
  format.setDepthBufferSize(24);
  format.setStencilBufferSize(8);
  QSurfaceFormat::setDefaultFormat(format);
}

VtkView::~VtkView() {
  makeCurrent();
  if (renderer_) window_->RemoveRenderer(renderer_);
  window_->Finalize();
  doneCurrent();
}

vtkRenderer* VtkView::renderer() const { return renderer_; }

void VtkView::setRenderer(vtkRenderer* renderer) {
  if (renderer_) window_->RemoveRenderer(renderer_);
  renderer_ = renderer;
  if (renderer_) window_->AddRenderer(renderer_);
  update();
}

void VtkView::initializeGL() {
  window_->SetReadyForRendering(true);
  window_->SetMapped(true);
  window_->SetIsDirect(true);
  window_->SetForceMaximumHardwareLineWidth(1);
  window_->SetIsCurrent(true);
  window_->OpenGLInitContext();
}

void VtkView::resizeGL(int w, int h) {
  const double dpr = devicePixelRatioF();
  window_->SetSize(static_cast<int>(w * dpr), static_cast<int>(h * dpr));
}

void VtkView::paintGL() {
  window_->SetReadyForRendering(true);
  window_->SetIsCurrent(true);
  if (renderer_) renderer_->ResetCameraClippingRange();
  window_->Render();
  window_->SetReadyForRendering(false);
}

void VtkView::rotateBy(double azimuthDeg, double elevationDeg) {
  if (!renderer_) return;
  vtkCamera* cam = renderer_->GetActiveCamera();
  cam->Azimuth(azimuthDeg);
  cam->Elevation(elevationDeg);
  cam->OrthogonalizeViewUp();
  update();
}

void VtkView::zoomBy(double factor) {
  if (!renderer_ || !(factor > 0)) return;
  renderer_->GetActiveCamera()->Dolly(factor);
  update();
}

void VtkView::pan(QPoint delta) {
  if (!renderer_) return;
  vtkCamera* cam = renderer_->GetActiveCamera();
  double fp[3], pos[3], up[3], dir[3];
  cam->GetFocalPoint(fp);
  cam->GetPosition(pos);
  cam->GetViewUp(up);
  cam->GetDirectionOfProjection(dir);
  double right[3] = {dir[1] * up[2] - dir[2] * up[1], dir[2] * up[0] - dir[0] * up[2],
                     dir[0] * up[1] - dir[1] * up[0]};
  const double dist = cam->GetDistance();
  const double scale = 2.0 * dist * std::tan(cam->GetViewAngle() * M_PI / 360.0) /
                       std::max(1, height());
  for (int i = 0; i < 3; ++i) {
    const double shift = (-delta.x() * right[i] + delta.y() * up[i]) * scale;
    fp[i] += shift;
    pos[i] += shift;
  }
  cam->SetFocalPoint(fp);
  cam->SetPosition(pos);
  update();
}

void VtkView::mousePressEvent(QMouseEvent* e) {
  dragging_ = e->button();
  panning_ = e->button() == Qt::MiddleButton ||
             (e->button() == Qt::LeftButton && (e->modifiers() & Qt::ShiftModifier));
  last_ = e->position().toPoint();
}

void VtkView::mouseMoveEvent(QMouseEvent* e) {
  if (dragging_ == Qt::NoButton) return;
  const QPoint p = e->position().toPoint();
  const QPoint d = p - last_;
  last_ = p;
  if (panning_) {
    pan(d);
  } else if (dragging_ == Qt::LeftButton) {
    rotateBy(-0.4 * d.x(), 0.4 * d.y());
  } else if (dragging_ == Qt::RightButton) {
    zoomBy(std::pow(1.01, -d.y()));
  }
}

void VtkView::mouseReleaseEvent(QMouseEvent*) {
  dragging_ = Qt::NoButton;
  panning_ = false;
}

void VtkView::mouseDoubleClickEvent(QMouseEvent*) {
  if (reset_) reset_();
  update();
}

void VtkView::wheelEvent(QWheelEvent* e) {
  zoomBy(std::pow(1.1, e->angleDelta().y() / 120.0));
  e->accept();
}

}  // namespace flexarm
