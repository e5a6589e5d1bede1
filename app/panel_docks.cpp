#include "app/panel_docks.h"

#include <QAction>
#include <QDialog>
#include <QDockWidget>
#include <QKeyEvent>
#include <QLabel>
#include <QLineEdit>
#include <QListWidget>
#include <QMainWindow>
#include <QMenu>
#include <QScreen>
#include <QScrollArea>
#include <QTimer>
#include <QVBoxLayout>
#include <algorithm>

namespace flexarm {
namespace {

// Narrower or lower than this, the screen is a laptop's: one tab group the whole height.
constexpr int kWideWidth = 1600, kWideHeight = 900;

// Up and Down in the filter field move through the list.
class SwitcherKeys : public QObject {
 public:
  SwitcherKeys(QListWidget* list, QObject* parent) : QObject(parent), list_(list) {}
  bool eventFilter(QObject* watched, QEvent* e) override {
    if (e->type() != QEvent::KeyPress) return QObject::eventFilter(watched, e);
    const int key = static_cast<QKeyEvent*>(e)->key();
    if (key != Qt::Key_Up && key != Qt::Key_Down) return QObject::eventFilter(watched, e);
    int row = list_->currentRow();
    do {
      row += key == Qt::Key_Down ? 1 : -1;
    } while (row >= 0 && row < list_->count() && list_->item(row)->isHidden());
    if (row >= 0 && row < list_->count()) list_->setCurrentRow(row);
    return true;
  }

 private:
  QListWidget* list_;
};

}  // namespace

PanelDocks::PanelDocks(QMainWindow* window, QMenu* viewMenu)
    : QObject(window), window_(window), viewMenu_(viewMenu) {
  // The tabs above the panels, where a tabbed window has them.
  window_->setTabPosition(Qt::AllDockWidgetAreas, QTabWidget::North);
  QAction* find = viewMenu_->addAction(tr("&Panels..."), this, &PanelDocks::openSwitcher);
  find->setObjectName("panelSwitcherAction");
  find->setShortcut(QKeySequence("Ctrl+K"));
  find->setToolTip(tr("Go to a panel by typing part of its name"));
  QAction* arrangeAction = viewMenu_->addAction(tr("&Arrange panels for this screen"), this, [this] {
    const QScreen* s = window_->screen();
    arrange(layoutFor(s ? s->availableGeometry().size() : window_->size()));
  });
  arrangeAction->setObjectName("arrangePanelsAction");
  viewMenu_->addSeparator();
}

QDockWidget* PanelDocks::add(QWidget* panel, const QString& title, const char* objectName,
                             const QString& shortcut, Place place, bool scroll) {
  auto* dock = new QDockWidget(title, window_);
  dock->setObjectName(objectName);
  if (!scroll) {
    dock->setWidget(panel);
  } else {
    // A tall panel scrolls in a short dock, so that the window fits a 1366x768 screen.
    auto* area = new QScrollArea(dock);
    area->setObjectName(QString(objectName) + "Scroll");
    area->setWidget(panel);
    area->setWidgetResizable(true);
    area->setFrameShape(QFrame::NoFrame);
    dock->setWidget(area);
  }
  window_->addDockWidget(Qt::RightDockWidgetArea, dock);
  // The menu entry shows the panel and brings it forward, whatever state it was in: a
  // toggle would hide a panel that is "visible" behind the other tabs.
  QAction* go = viewMenu_->addAction(title, this, [this, dock] { showPanel(dock); });
  go->setObjectName(QString(objectName) + "Action");
  go->setShortcut(QKeySequence(shortcut));
  go->setShortcutContext(Qt::WindowShortcut);
  // Docked again after floating: to the front of its tab group, not behind another tab.
  connect(dock, &QDockWidget::topLevelChanged, this, [dock](bool floating) {
    if (!floating) QTimer::singleShot(0, dock, [dock] { dock->raise(); });
  });
  panels_.push_back({dock, title, QKeySequence(shortcut), place});
  return dock;
}

void PanelDocks::showPanel(QDockWidget* dock) {
  if (!dock) return;
  if (dock->isHidden() && !dock->isFloating()) {
    // A closed dock comes back into the tab group of the first panel still docked.
    for (const Panel& p : panels_)
      if (p.dock != dock && !p.dock->isHidden() && !p.dock->isFloating()) {
        window_->tabifyDockWidget(p.dock, dock);
        break;
      }
  }
  dock->show();
  dock->raise();
  if (QWidget* w = dock->widget()) w->setFocus(Qt::ShortcutFocusReason);
}

PanelDocks::Layout PanelDocks::layoutFor(QSize available) {
  return available.width() < kWideWidth || available.height() < kWideHeight ? Layout::Compact : Layout::Wide;
}

const char* PanelDocks::toString(Layout layout) { return layout == Layout::Compact ? "compact" : "wide"; }

void PanelDocks::arrange(Layout layout) {
  layout_ = layout;
  if (panels_.empty()) return;
  QDockWidget* anchor = nullptr;  // the tab group
  std::vector<QDockWidget*> own;
  // Every dock out of its place first, then the anchor back, the panels of their own split
  // off it before it holds tabs (a dock split from a tabbed one would become one more tab),
  // and the others tabbed with it. Never all stacked at once: the window would grow to hold
  // eleven docks' least heights.
  for (const Panel& p : panels_) {
    p.dock->setFloating(false);
    window_->removeDockWidget(p.dock);
  }
  for (const Panel& p : panels_) {
    if (layout == Layout::Wide && p.place == Place::Own) own.push_back(p.dock);
    else if (!anchor) anchor = p.dock;
  }
  if (!anchor) return;
  window_->addDockWidget(Qt::RightDockWidgetArea, anchor);
  anchor->show();
  for (QDockWidget* d : own) {
    window_->splitDockWidget(anchor, d, Qt::Vertical);
    d->show();
  }
  for (const Panel& p : panels_)
    if (p.dock != anchor && std::find(own.begin(), own.end(), p.dock) == own.end()) {
      window_->tabifyDockWidget(anchor, p.dock);
      p.dock->show();
    }
  anchor->raise();
  // The docks take a little more than half the width: the Log panel keeps the rest.
  const int width = std::max(420, window_->width() * 11 / 20);
  window_->resizeDocks({anchor}, {width}, Qt::Horizontal);
  if (!own.empty()) {
    QList<QDockWidget*> column{anchor};
    QList<int> heights{window_->height() * 3 / 5};
    for (QDockWidget* d : own) {
      column << d;
      heights << window_->height() * 2 / 5 / static_cast<int>(own.size());
    }
    window_->resizeDocks(column, heights, Qt::Vertical);
  }
}

QDialog* PanelDocks::switcher() {
  if (switcher_) return switcher_;
  switcher_ = new QDialog(window_, Qt::Popup);
  switcher_->setObjectName("panelSwitcher");
  auto* filter = new QLineEdit(switcher_);
  filter->setObjectName("panelSwitcherFilter");
  filter->setPlaceholderText(tr("Panel name"));
  filter->setToolTip(tr("Type part of a panel's name; Enter shows it"));
  auto* list = new QListWidget(switcher_);
  list->setObjectName("panelSwitcherList");
  list->setToolTip(tr("Every panel with its shortcut"));
  auto* layout = new QVBoxLayout(switcher_);
  layout->setContentsMargins(6, 6, 6, 6);
  layout->addWidget(new QLabel(tr("Go to panel"), switcher_));
  layout->addWidget(filter);
  layout->addWidget(list);
  filter->installEventFilter(new SwitcherKeys(list, switcher_));
  auto refill = [this, list, filter] {
    list->clear();
    for (const Panel& p : panels_) {
      auto* item = new QListWidgetItem(
          QString("%1\t%2").arg(p.title, p.shortcut.toString(QKeySequence::NativeText)), list);
      item->setData(Qt::UserRole, QVariant::fromValue<QObject*>(p.dock));
    }
    filter->clear();
    list->setCurrentRow(0);
  };
  connect(filter, &QLineEdit::textChanged, list, [list](const QString& text) {
    int first = -1;
    for (int i = 0; i < list->count(); ++i) {
      const bool match = list->item(i)->text().section('\t', 0, 0).contains(text, Qt::CaseInsensitive);
      list->item(i)->setHidden(!match);
      if (match && first < 0) first = i;
    }
    list->setCurrentRow(first);
  });
  auto choose = [this, list](QListWidgetItem* item) {
    if (!item) return;
    switcher_->hide();
    showPanel(qobject_cast<QDockWidget*>(item->data(Qt::UserRole).value<QObject*>()));
  };
  connect(filter, &QLineEdit::returnPressed, list, [list, choose] { choose(list->currentItem()); });
  connect(list, &QListWidget::itemActivated, list, choose);
  connect(list, &QListWidget::itemClicked, list, choose);
  switcherRefill_ = refill;  // the list is filled each time it opens
  return switcher_;
}

void PanelDocks::openSwitcher() {
  QDialog* d = switcher();
  switcherRefill_();
  d->resize(320, std::min(420, 90 + 22 * static_cast<int>(panels_.size())));
  d->move(window_->mapToGlobal(QPoint((window_->width() - d->width()) / 2, window_->height() / 5)));
  d->show();
  d->findChild<QLineEdit*>("panelSwitcherFilter")->setFocus();
}

}  // namespace flexarm
