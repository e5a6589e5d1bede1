#include "app/gui_main.h"

#include <QApplication>
#include <QTimer>
#include <iostream>

#include "app/main_window.h"
#include "app/session_controller.h"
#include "widgets/arm/vtk_view.h"
#include "widgets/file_output.h"

namespace flexarm {

int runGui(int argc, char** argv, const std::string& log, const std::string& screenshot) {
  // VTK's OpenGL2 backend needs a 3.2 core profile before the application object exists.
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName("FlexArm");
  QApplication::setApplicationName("FlexArm");
  QApplication::setApplicationVersion(FLEXARM_VERSION);
  MainWindow window;
  // A screenshot run asks nothing at start (the recovery question is queued, not yet shown).
  if (!screenshot.empty()) window.sessionController()->setOfferRecovery(false);
  window.show();
  int code = 0;
  if (!screenshot.empty()) {
    auto save = [&] {
      QTimer::singleShot(700, &window, [&] {
        QString problem;
        if (!saveImageFile(window.grab().toImage(), QString::fromStdString(screenshot), nullptr, &problem)) {
          std::cerr << "flexarm: cannot write " << screenshot << ": " << problem.toStdString() << "\n";
          code = 3;
        }
        QApplication::quit();
      });
    };
    QObject::connect(&window, &MainWindow::logOpened, &window, save);
    QObject::connect(&window, &MainWindow::openFailed, &window, [&](const QString& m) {
      std::cerr << "flexarm: " << m.toStdString() << "\n";
      code = 3;
      save();
    });
    if (log.empty()) save();
  }
  if (!log.empty()) window.openFile(QString::fromStdString(log));
  const int rc = app.exec();
  return code ? code : rc;
}

}  // namespace flexarm
