#include "app/gui_main.h"

#include <QApplication>

#include "app/main_window.h"
#include "widgets/arm/vtk_view.h"

namespace flexarm {

int runGui(int argc, char** argv) {
  // VTK's OpenGL2 backend needs a 3.2 core profile before the application object exists.
  VtkView::installDefaultSurfaceFormat();
  QApplication app(argc, argv);
  QApplication::setOrganizationName("FlexArm");
  QApplication::setApplicationName("FlexArm");
  QApplication::setApplicationVersion(FLEXARM_VERSION);
  MainWindow window;
  window.show();
  const QStringList args = QApplication::arguments();
  if (args.size() > 1) window.openFile(args.at(1));
  return app.exec();
}

}  // namespace flexarm
