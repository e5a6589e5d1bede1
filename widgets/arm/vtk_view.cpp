#include "widgets/arm/vtk_view.h"

#include <QElapsedTimer>
#include <QMouseEvent>
#include <QOffscreenSurface>
#include <QOpenGLContext>
#include <QOpenGLFunctions>
#include <QPainter>
#include <QSurfaceFormat>
#include <QWheelEvent>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkOpenGLFramebufferObject.h>
#include <vtkRenderer.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#ifndef GL_BGRA
#define GL_BGRA 0x80E1
#endif
#ifndef GL_READ_FRAMEBUFFER
#define GL_READ_FRAMEBUFFER 0x8CA8
#endif

namespace flexarm {

VtkView::VtkView(QWidget* parent)
    : QWidget(parent), window_(vtkSmartPointer<vtkGenericOpenGLRenderWindow>::New()) {
  window_->SetOwnContext(false);
  window_->SetFrameBlitModeToNoBlit();  // the picture is read from VTK's display framebuffer
  window_->SetMultiSamples(0);
  // VTK asks for its context when it needs it outside a render (e.g. to free its buffers).
  auto makeCurrent = vtkSmartPointer<vtkCallbackCommand>::New();
  makeCurrent->SetClientData(this);
  makeCurrent->SetCallback([](vtkObject*, unsigned long, void* self, void*) {
    static_cast<VtkView*>(self)->makeCurrent();
  });
  window_->AddObserver(vtkCommand::WindowMakeCurrentEvent, makeCurrent);
  setAttribute(Qt::WA_OpaquePaintEvent);
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
  if (initialized_ && makeCurrent()) {
    if (renderer_) window_->RemoveRenderer(renderer_);
    window_->Finalize();
    context_->doneCurrent();
  }
  window_->RemoveAllObservers();
}

vtkRenderer* VtkView::renderer() const { return renderer_; }

void VtkView::setRenderer(vtkRenderer* renderer) {
  if (renderer_) window_->RemoveRenderer(renderer_);
  renderer_ = renderer;
  if (renderer_) window_->AddRenderer(renderer_);
  requestRender();
}

void VtkView::requestRender() {
  dirty_ = true;
  update();
}

bool VtkView::makeCurrent() {
  if (failed_) return false;
  if (!context_) {
    context_ = std::make_unique<QOpenGLContext>();
    context_->setFormat(QSurfaceFormat::defaultFormat());
    surface_ = std::make_unique<QOffscreenSurface>();
    surface_->setFormat(QSurfaceFormat::defaultFormat());
    surface_->create();
    if (!context_->create() || !surface_->isValid()) {
      failed_ = true;
      return false;
    }
  }
  const bool ok = context_->makeCurrent(surface_.get());
  window_->SetIsCurrent(ok);
  return ok;
}

void VtkView::render() {
  QElapsedTimer clock;
  clock.start();
  const qreal dpr = devicePixelRatioF();
  const QSize size(std::max(1, static_cast<int>(std::lround(width() * dpr))),
                   std::max(1, static_cast<int>(std::lround(height() * dpr))));
  dirty_ = false;
  if (!renderer_ || !makeCurrent()) return;
  if (!initialized_) {
    window_->SetReadyForRendering(true);
    window_->SetMapped(true);
    window_->SetIsDirect(true);
    window_->SetForceMaximumHardwareLineWidth(1);
    window_->SetIsCurrent(true);
    window_->OpenGLInitContext();
    initialized_ = true;
  }
  window_->SetSize(size.width(), size.height());
  window_->SetReadyForRendering(true);
  renderer_->ResetCameraClippingRange();
  window_->Render();
  window_->SetReadyForRendering(false);
  // Read VTK's display framebuffer as BGRA, which is QImage's RGB32 in memory (the alpha VTK
  // leaves in its background is ignored: the scene is opaque), and turn it upright.
  vtkOpenGLFramebufferObject* display = window_->GetDisplayFramebuffer();
  if (!display) return;
  display->Bind(GL_READ_FRAMEBUFFER);
  display->ActivateReadBuffer(0);
  const int w = size.width(), h = size.height();
  pixels_.resize(static_cast<std::size_t>(w) * h * 4);
  QOpenGLFunctions* gl = context_->functions();
  gl->glPixelStorei(GL_PACK_ALIGNMENT, 4);
  gl->glReadPixels(0, 0, w, h, GL_BGRA, GL_UNSIGNED_BYTE, pixels_.data());
  if (image_.size() != size || image_.format() != QImage::Format_RGB32)
    image_ = QImage(size, QImage::Format_RGB32);
  for (int y = 0; y < h; ++y)
    std::memcpy(image_.scanLine(y), pixels_.data() + static_cast<std::size_t>(h - 1 - y) * w * 4,
                static_cast<std::size_t>(w) * 4);
  image_.setDevicePixelRatio(dpr);
  const double s = clock.nsecsElapsed() * 1e-9;
  ++stats_.frames;
  stats_.renderSeconds += s;
  stats_.worstSeconds = std::max(stats_.worstSeconds, s);
}

void VtkView::renderIfNeeded() {
  const qreal dpr = devicePixelRatioF();
  if (dirty_ || image_.isNull() ||
      image_.size() != QSize(std::lround(width() * dpr), std::lround(height() * dpr)))
    render();
}

QImage VtkView::grabFramebuffer() {
  renderIfNeeded();
  QImage out = image_.copy();
  if (overlay_ && !out.isNull()) {
    QPainter painter(&out);
    overlay_(painter, rect());
  }
  return out;
}

void VtkView::paintEvent(QPaintEvent*) {
  renderIfNeeded();
  QPainter painter(this);
  if (image_.isNull())
    painter.fillRect(rect(), QColor(40, 46, 56));
  else
    painter.drawImage(QPoint(0, 0), image_);
  if (overlay_) overlay_(painter, rect());
}

void VtkView::resizeEvent(QResizeEvent*) { dirty_ = true; }

void VtkView::rotateBy(double azimuthDeg, double elevationDeg) {
  if (!renderer_) return;
  vtkCamera* cam = renderer_->GetActiveCamera();
  cam->Azimuth(azimuthDeg);
  cam->Elevation(elevationDeg);
  cam->OrthogonalizeViewUp();
  requestRender();
}

void VtkView::zoomBy(double factor) {
  if (!renderer_ || !(factor > 0)) return;
  renderer_->GetActiveCamera()->Dolly(factor);
  requestRender();
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
  requestRender();
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
  requestRender();
}

void VtkView::wheelEvent(QWheelEvent* e) {
  zoomBy(std::pow(1.1, e->angleDelta().y() / 120.0));
  e->accept();
}

}  // namespace flexarm
