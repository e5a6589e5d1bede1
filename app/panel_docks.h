#pragma once
// The window's panels as docks, registered in one place: PanelDocks::add gives a panel its
// dock, a View menu entry whose shortcut shows the panel and brings it to the front (never
// hides it), a line in the panel switcher (Ctrl+K: type part of a name, Enter), and a place
// in the layout chosen for the screen. A new panel joins all of them with its one add() line
// in MainWindow's constructor; nothing here names a panel.
//
// Layouts: compact (a laptop screen, narrower than 1600 or lower than 900 px) puts every
// panel in one tab group on the right that takes the whole height; wide puts the panels that
// ask for a place of their own (the Arm view) below that tab group. A panel whose dock is
// floated and docked again comes back to the front of its tab group.
#include <QKeySequence>
#include <QObject>
#include <QSize>
#include <QString>
#include <functional>
#include <vector>

class QDialog;
class QDockWidget;
class QMainWindow;
class QMenu;
class QWidget;

namespace flexarm {

class PanelDocks : public QObject {
  Q_OBJECT
 public:
  // Where a panel goes in the wide layout (in the compact one every panel is a tab).
  enum class Place { Tabs, Own };
  enum class Layout { Compact, Wide };
  struct Panel {
    QDockWidget* dock = nullptr;
    QString title;
    QKeySequence shortcut;
    Place place = Place::Tabs;
  };

  PanelDocks(QMainWindow* window, QMenu* viewMenu);

  // Puts panel in a new dock named objectName (its content scrolls in a short dock unless
  // the panel fills any size itself, scroll false) and registers it everywhere.
  QDockWidget* add(QWidget* panel, const QString& title, const char* objectName, const QString& shortcut,
                   Place place = Place::Tabs, bool scroll = true);
  const std::vector<Panel>& panels() const { return panels_; }
  // Shows the dock, docked if it was closed, at the front of its tab group, with the focus.
  void showPanel(QDockWidget* dock);

  // The layout for a screen of this available size.
  static Layout layoutFor(QSize available);
  static const char* toString(Layout layout);
  // Puts every registered dock in its place for the layout, docked and shown, the first
  // panel at the front; the docks take about half the window's width.
  void arrange(Layout layout);
  Layout layout() const { return layout_; }

  // The panel switcher: a list of the panels by name with their shortcuts, filtered as one
  // types; Enter (or a click) shows the chosen one as showPanel does. Created on first use.
  QDialog* switcher();
  void openSwitcher();

 private:
  QMainWindow* window_;
  QMenu* viewMenu_;
  std::vector<Panel> panels_;
  Layout layout_ = Layout::Wide;
  QDialog* switcher_ = nullptr;
  std::function<void()> switcherRefill_;
};

}  // namespace flexarm
