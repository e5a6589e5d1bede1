// The window as it fits a laptop screen (issue 20, problems 4-8): every dock, docked, at
// 1366x768 and 1920x1080 with nothing clipped (children inside their parents, text no wider
// than its widget by QFontMetrics), the LQG panel reflowed with sliders that step, axes with
// units, typed ranges, the plot tools (reset zoom, context menu, export, panning limits), the
// E/V/Z keys, and the report's layout read back with pdftotext. Screenshots of every dock go
// to the build tree's screenshots/ folder.
#include <QAbstractButton>
#include <QCheckBox>
#include <QComboBox>
#include <QDockWidget>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QMenu>
#include <QProcess>
#include <QRegularExpression>
#include <QPushButton>
#include <QRadioButton>
#include <QScrollArea>
#include <QScrollBar>
#include <QSettings>
#include <QSignalSpy>
#include <QSlider>
#include <QSpinBox>
#include <QStandardPaths>
#include <QStatusBar>
#include <QTableWidget>
#include <QTemporaryDir>
#include <QTextDocument>
#include <QToolButton>
#include <QtTest>
#include <memory>
#include <qcustomplot.h>

#include "app/main_window.h"
#include "app/panel_docks.h"
#include "app/report_writer.h"
#include "core/session/report.h"
#include "widget_test_support.h"
#include "widgets/arm_panel.h"
#include "widgets/bode_panel.h"
#include "widgets/plots/bode_plot.h"
#include "widgets/compare_panel.h"
#include "widgets/log_panel.h"
#include "widgets/log_slider.h"
#include "widgets/lqg_panel.h"
#include "widgets/model_panel.h"
#include "widgets/playhead.h"
#include "widgets/plots/plot_tools.h"
#include "widgets/preprocess_panel.h"
#include "widgets/residuals_panel.h"
#include "widgets/transport_bar.h"
#include "widgets/workspace.h"

using namespace flexarm;

namespace {

const QString kSampleLog = QString(FLEXARM_SAMPLE_DIR) + "/three_mass_estimation_chirp.csv";
const char* const kDocks[] = {"preprocessDock", "armDock",       "modelDock",     "fitDock",
                              "bodeDock",       "compareDock",   "residualsDock", "lqgDock",
                              "discoveryDock",  "diagnosisDock", "recursiveDock", "fleetDock"};

QString describe(const QWidget* w) {
  return QString("%1 %2").arg(w->metaObject()->className(), w->objectName());
}

// True when w lies inside a widget whose children are not laid out for the eye (the
// internals of item views, plots, combo boxes, spin boxes, scroll bars).
bool internal(const QWidget* w, const QWidget* root) {
  for (const QWidget* p = w->parentWidget(); p && p != root; p = p->parentWidget())
    if (qobject_cast<const QAbstractItemView*>(p) || qobject_cast<const QComboBox*>(p) ||
        qobject_cast<const QAbstractSpinBox*>(p) || qobject_cast<const QCustomPlot*>(p))
      return true;
  return qobject_cast<const QScrollBar*>(w) != nullptr;
}

// A control a user operates: a button, combo box, spin box or slider.
bool isControl(const QWidget* w) {
  return qobject_cast<const QAbstractButton*>(w) || qobject_cast<const QComboBox*>(w) ||
         qobject_cast<const QAbstractSpinBox*>(w) || qobject_cast<const QSlider*>(w);
}

// Widest line of a plain text.
int textWidth(const QFontMetrics& fm, const QString& text) {
  int widest = 0;
  for (const QString& line : text.split('\n')) widest = std::max(widest, fm.horizontalAdvance(line));
  return widest;
}

// Every visible descendant of root whose geometry leaves its parent or whose text is wider
// than it: labels, buttons, check boxes, line edits, spin boxes, tables' cells and headers,
// and the plots' titles and axis labels.
QStringList clipped(QWidget* root) {
  QStringList problems;
  for (QWidget* w : root->findChildren<QWidget*>()) {
    if (!w->isVisibleTo(root) || internal(w, root) || w->isWindow()) continue;
    QWidget* parent = w->parentWidget();
    // A scroll area's content may be larger than its viewport: that is what scrolls.
    const bool scrolled = parent && parent->objectName() == "qt_scrollarea_viewport";
    if (parent && !scrolled && !parent->rect().adjusted(-1, -1, 1, 1).contains(w->geometry()))
      problems << QString("%1 outside its parent %2 (%3,%4 %5x%6 in %7x%8)")
                      .arg(describe(w), describe(parent))
                      .arg(w->x()).arg(w->y()).arg(w->width()).arg(w->height())
                      .arg(parent->width()).arg(parent->height());
    const QFontMetrics fm = w->fontMetrics();
    auto check = [&](const QString& text, int need, int have) {
      if (need > have)
        problems << QString("%1: '%2' needs %3 px, has %4").arg(describe(w), text).arg(need).arg(have);
    };
    if (auto* l = qobject_cast<QLabel*>(w)) {
      if (!l->wordWrap() && !l->text().isEmpty() && !Qt::mightBeRichText(l->text()))
        check(l->text(), textWidth(fm, l->text()) + 2 * l->margin(), l->contentsRect().width());
    } else if (auto* c = qobject_cast<QCheckBox*>(w)) {
      check(c->text(), fm.horizontalAdvance(c->text()) + 18, c->width());
    } else if (auto* r = qobject_cast<QRadioButton*>(w)) {
      check(r->text(), fm.horizontalAdvance(r->text()) + 18, r->width());
    } else if (auto* b = qobject_cast<QPushButton*>(w)) {
      if (!b->text().isEmpty()) check(b->text(), fm.horizontalAdvance(b->text()) + 8, b->width());
    } else if (auto* t = qobject_cast<QToolButton*>(w)) {
      if (t->toolButtonStyle() != Qt::ToolButtonIconOnly && !t->text().isEmpty() &&
          (t->icon().isNull() || t->toolButtonStyle() != Qt::ToolButtonFollowStyle))
        check(t->text(), fm.horizontalAdvance(QString(t->text()).remove('&')) + 6, t->width());
    } else if (auto* e = qobject_cast<QLineEdit*>(w)) {
      check(e->text(), fm.horizontalAdvance(e->text()) + 6, e->width());
    } else if (auto* s = qobject_cast<QAbstractSpinBox*>(w)) {
      const QString text = s->text();
      check(text, fm.horizontalAdvance(text) + 6, s->width() - 16);
    } else if (auto* table = qobject_cast<QTableWidget*>(w)) {
      for (int col = 0; col < table->columnCount(); ++col) {
        if (table->isColumnHidden(col)) continue;
        const int width = table->columnWidth(col);
        if (auto* h = table->horizontalHeaderItem(col))
          check(h->text(), fm.horizontalAdvance(h->text()) + 4, width);
        if (table->wordWrap() && col == table->columnCount() - 1) continue;  // wraps in the cell
        for (int row = 0; row < table->rowCount(); ++row)
          if (auto* item = table->item(row, col))
            check(item->text(), QFontMetrics(item->font()).horizontalAdvance(item->text()) + 6, width);
      }
    } else if (auto* plot = qobject_cast<QCustomPlot*>(w)) {
      for (int i = 0; i < plot->plotLayout()->elementCount(); ++i)
        if (auto* title = qobject_cast<QCPTextElement*>(plot->plotLayout()->elementAt(i)))
          check(title->text(), QFontMetrics(title->font()).horizontalAdvance(title->text()), plot->width());
      for (QCPAxisRect* rect : plot->axisRects())
        for (QCPAxis* a : rect->axes())
          if (a->visible() && !a->label().isEmpty()) {
            const int need = textWidth(QFontMetrics(a->labelFont()), a->label());
            const bool vertical = a->orientation() == Qt::Vertical;
            check(a->label(), need, vertical ? rect->outerRect().height() : rect->outerRect().width());
          }
    }
  }
  return problems;
}

// The dock's visible region, in window coordinates, is inside the window.
bool insideWindow(const QWidget* w, const QWidget* window) {
  const QRect r(w->mapTo(window, QPoint(0, 0)), w->size());
  return window->rect().contains(r) && !w->visibleRegion().isEmpty();
}

}  // namespace

class LayoutTest : public QObject {
  Q_OBJECT
 private:
  MainWindow* window_ = nullptr;
  QTemporaryDir dir_;

  QDockWidget* dock(const char* name) const { return window_->findChild<QDockWidget*>(name); }

  // The window at a screen's size (less a task bar) with the docks arranged for that screen.
  void showAt(QSize size) {
    window_->resize(size);
    window_->docks()->arrange(PanelDocks::layoutFor(size + QSize(0, 40)));
    QTest::qWait(50);
    QApplication::processEvents();
  }

  // Raises each dock in turn, saves its screenshot and returns what is clipped in it.
  QStringList shootDocks(const QString& suffix) {
    QStringList problems;
    for (const char* name : kDocks) {
      QDockWidget* d = dock(name);
      if (!d) {
        problems << QString("no dock %1").arg(name);
        continue;
      }
      d->show();
      d->raise();
      QTest::qWait(80);
      QApplication::processEvents();
      if (d->isFloating()) problems << QString("%1 floats").arg(name);
      test::saveShot(d->grab().toImage(), QString("dock_%1_%2").arg(name, suffix));
      if (!insideWindow(d, window_)) problems << QString("%1 not inside the window").arg(name);
      // The panel is no wider than its dock: nothing hides to the right.
      if (auto* scroll = qobject_cast<QScrollArea*>(d->widget()))
        if (scroll->widget()->width() > scroll->viewport()->width())
          problems << QString("%1: panel %2 px wide in a %3 px dock").arg(name)
                          .arg(scroll->widget()->width()).arg(scroll->viewport()->width());
      for (const QString& p : clipped(d)) problems << QString("%1: %2").arg(name, p);
    }
    return problems;
  }

 private slots:
  void initTestCase() {
    QVERIFY(dir_.isValid());
    QSettings().clear();  // the default layout, not one a previous run left
    window_ = new MainWindow;
    window_->show();
    QVERIFY(QTest::qWaitForWindowExposed(window_));
    QSignalSpy opened(window_, &MainWindow::logOpened);
    window_->openFile(kSampleLog);
    QVERIFY(opened.wait(30000));
    // A physical model in the list, so Model, Bode, Compare and Residuals draw something.
    QVERIFY(window_->modelPanel()->newModel("three-mass") >= 0);
    QTest::qWait(200);
  }

  // Problem 4: the window fits a 1366x768 screen; the range table, status bar and Arm
  // controls are on it.
  void windowFitsLaptopScreens() {
    const QSize least = window_->minimumSizeHint().expandedTo(window_->minimumSize());
    QStringList parts;  // what asks for the room, should it not fit
    auto part = [&](const QString& name, const QWidget* w) {
      const QSize m = w->minimumSizeHint().expandedTo(w->minimumSize());
      parts << QString("%1 %2x%3").arg(name).arg(m.width()).arg(m.height());
    };
    part("central", window_->centralWidget());
    for (const char* name : kDocks) part(name, dock(name));
    QVERIFY2(least.height() <= 768 - 40 && least.width() <= 1366,
             qPrintable(QString("minimum %1x%2: %3").arg(least.width()).arg(least.height())
                            .arg(parts.join(", "))));
    for (QSize size : {QSize(1366, 768 - 40), QSize(1920, 1080 - 40)}) {
      showAt(size);
      QCOMPARE(window_->size(), size);
      const QString at = QString("%1x%2").arg(size.width()).arg(size.height());
      auto* rangeTable = window_->logPanel()->rangeTable();
      QVERIFY2(insideWindow(rangeTable, window_), qPrintable("range table at " + at));
      QVERIFY2(rangeTable->height() >= rangeTable->horizontalHeader()->height() +
                                           2 * rangeTable->rowHeight(0),
               qPrintable("range table rows cut at " + at));
      QVERIFY2(insideWindow(window_->statusBar(), window_), qPrintable("status bar at " + at));
      dock("armDock")->raise();
      QApplication::processEvents();
      for (const char* control : {"armMagnify", "armExaggeration"}) {
        auto* w = window_->armPanel()->findChild<QWidget*>(control);
        QVERIFY2(w && insideWindow(w, window_), qPrintable(QString(control) + " at " + at));
      }
      test::saveShot(window_->grab().toImage(), "layout_window_" + at);
    }
  }

  // Every dock, docked, at both sizes: nothing clipped.
  void docksUnclippedAt1366x768() {
    showAt(QSize(1366, 768 - 40));
    const QStringList problems = shootDocks("1366x768");
    QVERIFY2(problems.isEmpty(), qPrintable(problems.join("\n")));
  }

  void docksUnclippedAt1920x1080() {
    showAt(QSize(1920, 1080 - 40));
    const QStringList problems = shootDocks("1920x1080");
    QVERIFY2(problems.isEmpty(), qPrintable(problems.join("\n")));
  }

  // Problem 5: the LQG panel's plots keep their titles and legends outside the data, the
  // sliders step one position on a click in the track, the fields show whole numbers.
  void lqgPanelReflowsAndSlidersStep() {
    showAt(QSize(1366, 768 - 40));
    dock("lqgDock")->raise();
    QApplication::processEvents();
    LqgPanel* lqg = window_->lqgPanel();
    for (QCustomPlot* p : lqg->findChildren<QCustomPlot*>()) {
      QVERIFY2(!qobject_cast<QCPLayoutInset*>(p->legend->layout()),
               qPrintable(p->objectName() + ": legend over the data"));
    }
    lqg->setControlsShown(false);
    QApplication::processEvents();
    QVERIFY(!lqg->controlsShown());
    lqg->setControlsShown(true);
    LogSlider* q2 = lqg->findChild<LogSlider*>("q2");
    QVERIFY(q2);
    QCOMPARE(q2->slider()->pageStep(), 1);
    q2->setValue(1.0);
    const double before = q2->value();
    QSlider* s = q2->slider();
    // A click near the right end of the track moves one position: a factor 10^(1/10).
    QTest::mouseClick(s, Qt::LeftButton, Qt::NoModifier, QPoint(s->width() - 4, s->height() / 2));
    QVERIFY2(q2->value() > before, qPrintable(QString::number(q2->value())));
    QVERIFY2(std::abs(q2->value() / before - std::pow(10.0, 0.1)) < 1e-9,
             qPrintable(QString::number(q2->value())));
    // A typed small weight is shown whole.
    auto* field = q2->field();
    field->setText("0.00025");
    QVERIFY(QFontMetrics(field->font()).horizontalAdvance(field->text()) + 6 <= field->width());
  }

  // Problem 6: axes say quantity and unit; numbers are printed with sensible precision.
  void axesHaveQuantitiesAndUnits() {
    // Compare: the output channel's name and unit instead of "output".
    const Channel* y = window_->workspace()->current()->output();
    QVERIFY(y);
    QCustomPlot* compare = window_->comparePanel()->plot();
    const QString label = compare->yAxis->label();
    QVERIFY2(label.contains(QString::fromStdString(y->name)) && label.contains("[") &&
                 label != "output",
             qPrintable(label));
    // Every labelled axis of every plot of the window names a unit in brackets.
    QStringList missing;
    for (QCustomPlot* p : window_->findChildren<QCustomPlot*>())
      for (QCPAxisRect* rect : p->axisRects())
        for (QCPAxis* a : rect->axes())
          if (a->visible() && !a->label().isEmpty() && !(a->label().contains('[') || a->label().contains('(')))
            missing << p->objectName() + ": " + a->label();
    QVERIFY2(missing.isEmpty(), qPrintable(missing.join("\n")));
    // The spectrum's amplitude carries the channel's unit once a preview ran.
    QSignalSpy ready(window_->preprocessPanel(), &PreprocessPanel::previewReady);
    window_->preprocessPanel()->findChild<QSpinBox*>("factorSpin")->setValue(5);
    QVERIFY(ready.wait(20000));
    QCustomPlot* spectrum = window_->preprocessPanel()->findChild<QCustomPlot*>("spectrumPlot");
    QVERIFY2(spectrum->yAxis->label().contains('['), qPrintable(spectrum->yAxis->label()));
    // Band level in percent.
    auto* level = window_->bodePanel()->findChild<QDoubleSpinBox*>("bodeLevelSpin");
    QCOMPARE(level->text(), QString("99 %"));
    // The speed box is labelled.
    auto* speed = window_->findChild<QLabel*>("speedLabel");
    QVERIFY(speed && speed->buddy() && speed->buddy()->objectName() == "speedCombo");
    // The Arm readout prints a motor at rest as 0, not 5e-22.
    window_->playhead()->setTime(0.0);
    QApplication::processEvents();
    const QString status = window_->armPanel()->statusText();
    QVERIFY2(!status.contains("e-"), qPrintable(status));
  }

  // Problem 7: ranges typed exactly; reset zoom, context menu and export on every plot;
  // panning stops at the log's start; E/V/Z keys.
  void rangesCanBeTyped() {
    LogPanel* log = window_->logPanel();
    QTableWidget* table = log->rangeTable();
    table->item(0, 1)->setText("0.5");
    table->item(0, 2)->setText("12");
    const auto r = window_->workspace()->range(RangeKind::Estimation);
    QVERIFY(r.has_value());
    QCOMPARE(r->start, 0.5);
    QCOMPARE(r->end, 12.0);
    QCOMPARE(table->item(0, 1)->text(), QString("0.5"));
    // Shown to the log's resolution (a tenth of its sample time), not a float's noise.
    table->item(0, 1)->setText("0.5119999871");
    QCOMPARE(table->item(0, 1)->text(), QString("0.512"));
    table->item(0, 1)->setText("0.5");
    // Nonsense is refused and the range stays.
    table->item(0, 2)->setText("twelve");
    QCOMPARE(window_->workspace()->range(RangeKind::Estimation)->end, 12.0);
    QString why;
    QVERIFY(!log->setRangeText(RangeKind::Validation, "-3", "4", &why));
    QVERIFY2(why.contains("outside"), qPrintable(why));
  }

  void everyPlotHasResetZoomAndContextMenu() {
    const auto plots = window_->findChildren<QCustomPlot*>();
    QVERIFY(plots.size() >= 15);
    for (QCustomPlot* p : plots) {
      PlotTools* tools = PlotTools::of(p);
      QVERIFY2(tools, qPrintable(p->objectName() + " has no plot tools"));
      QCOMPARE(p->contextMenuPolicy(), Qt::CustomContextMenu);
      std::unique_ptr<QMenu> menu(tools->createMenu(nullptr));
      QStringList names;
      for (QAction* a : menu->actions()) names << a->objectName();
      for (const char* action : {"resetZoom", "exportPlot", "copyData"})
        QVERIFY2(names.contains(action), qPrintable(p->objectName() + " lacks " + action));
    }
    // Double click resets the Log panel's zoom to the whole log.
    LogPanel* log = window_->logPanel();
    QCPAxis* time = log->channelRect(0)->axis(QCPAxis::atBottom);
    time->setRange(3.0, 4.0);
    const QPoint at = log->channelRect(0)->center();
    QTest::mouseDClick(log->plot(), Qt::LeftButton, Qt::NoModifier, at);
    QCOMPARE(time->range().size(), window_->workspace()->current()->duration());
    // Panning cannot run into negative time: a pan to -5 s stops at the log's start.
    time->setRange(-5.0, 5.0);
    QCOMPARE(time->range().lower, window_->workspace()->current()->startTime);
    QCOMPARE(time->range().size(), 10.0);
    // The Bode plot: double click rescales after a zoom, the export writes every format.
    QCustomPlot* bode = window_->bodePanel()->plot()->plot();
    QVERIFY(bode);
    PlotTools* tools = PlotTools::of(bode);
    for (const QString& ext : PlotTools::exportSuffixes()) {
      const QString path = dir_.filePath("bode." + ext);
      QString err;
      QVERIFY2(tools->exportTo(path, &err), qPrintable(err));
      QVERIFY(QFileInfo(path).size() > 100);
    }
    QFile csv(dir_.filePath("bode.csv"));
    QVERIFY(csv.open(QIODevice::ReadOnly));
    const QString header = QString::fromUtf8(csv.readLine());
    QVERIFY2(header.startsWith("series,x,y"), qPrintable(header));
    QVERIFY(QString::fromUtf8(csv.readAll()).contains("frequency [rad/s]"));
  }

  void rangeKeysWorkWithoutTakingLetters() {
    LogPanel* log = window_->logPanel();
    log->setMode(LogPanel::Mode::Navigate);
    window_->activateWindow();
    (void)QTest::qWaitForWindowActive(window_);  // shortcuts of the window need it active
    log->plot()->setFocus();
    QApplication::processEvents();
    QTest::keyClick(log->plot(), Qt::Key_E);
    QCOMPARE(log->mode(), LogPanel::Mode::SelectEstimation);
    QTest::keyClick(log->plot(), Qt::Key_V);
    QCOMPARE(log->mode(), LogPanel::Mode::SelectValidation);
    QTest::keyClick(log->plot(), Qt::Key_Z);
    QCOMPARE(log->mode(), LogPanel::Mode::Navigate);
    // A text field keeps its letters.
    dock("lqgDock")->raise();
    QApplication::processEvents();
    auto* field = window_->lqgPanel()->findChild<QLineEdit*>("saturationLimit");
    QVERIFY(field);
    field->setFocus();
    field->clear();
    QTest::keyClick(field, Qt::Key_E);
    QCOMPARE(field->text(), QString("e"));
    QCOMPARE(log->mode(), LogPanel::Mode::Navigate);
    field->setText("2.5");
  }

  // Every control a user can reach in every dock and the transport bar says what it does (its
  // unit, the seed's equation where one applies), shown or hidden for the moment.
  void controlsHaveTooltips() {
    QList<QWidget*> roots;
    for (QDockWidget* d : window_->findChildren<QDockWidget*>()) roots << d;
    roots << window_->transportBar();
    QVERIFY(roots.size() >= 12);
    QStringList bare;
    int checked = 0;
    for (QWidget* root : roots)
      for (QWidget* w : root->findChildren<QWidget*>()) {
        if (!isControl(w) || w->objectName().startsWith("qt_") || internal(w, root)) continue;
        ++checked;
        if (!w->toolTip().isEmpty()) continue;
        const auto* b = qobject_cast<const QAbstractButton*>(w);
        bare << QString("%1: %2 \"%3\"").arg(root->objectName(), describe(w), b ? b->text() : QString());
      }
    QVERIFY(checked > 60);
    for (const QString& b : bare) qInfo("no tooltip: %s", qPrintable(b));
    QVERIFY2(bare.isEmpty(), qPrintable(QString("%1 controls without a tooltip:\n%2")
                                            .arg(bare.size()).arg(bare.join("\n"))));
  }

  // Problem 8: the report says "Log" once, keeps table headings whole, wraps the checksum.
  void reportLayoutReadsWell() {
    if (QStandardPaths::findExecutable("pdftotext").isEmpty()) QSKIP("pdftotext not installed");
    Report r;
    r.flexarmVersion = FLEXARM_VERSION;
    r.session = "layout.flexarm";
    r.logs.push_back({"log", "/a/rather/long/folder/name/three_mass_estimation_chirp.csv",
                      std::string(64, 'a').replace(0, 8, "0123abcd"), ""});
    ReportSection s;
    s.title = "Fit three-mass estimate";
    ReportTable t;
    t.caption = "Estimates";
    t.header = {"Parameter", "Estimate", "Std", "Interval low", "Interval high", "Unit",
                "Significant", "Identifiable", "Correlated with"};
    t.rows.push_back({"J_m", "0.005347", "0.0001", "0.0051", "0.0056", "kg m^2", "yes", "yes",
                      "k_g (0.93), d_g (0.41)"});
    s.tables.push_back(t);
    r.sections.push_back(s);
    const QString pdf = dir_.filePath("report.pdf");
    QString why;
    QVERIFY2(writeReportPdf(r, pdf, &why), qPrintable(why));
    QProcess p;
    p.start("pdftotext", {"-layout", pdf, "-"});
    QVERIFY(p.waitForFinished(20000));
    QString text = QString::fromUtf8(p.readAllStandardOutput());
    text.replace(QChar(0xFB01), "fi").replace(QChar(0xFB02), "fl");  // the font's ligatures
    QVERIFY2(!text.contains("Log log:"), qPrintable(text));
    QVERIFY2(text.contains("Log: /a/rather"), qPrintable(text));
    for (const std::string& heading : t.header)
      for (const QString& word : QString::fromStdString(heading).split(' '))
        QVERIFY2(text.contains(word), qPrintable(word + " broken in\n" + text));
    // Nothing runs off the page: every word ends left of the right margin.
    QProcess box;
    box.start("pdftotext", {"-bbox", pdf, "-"});
    QVERIFY(box.waitForFinished(20000));
    const QString boxes = QString::fromUtf8(box.readAllStandardOutput());
    const auto page = QRegularExpression("<page width=\"([0-9.]+)\"").match(boxes);
    QVERIFY(page.hasMatch());
    const double pageWidth = page.captured(1).toDouble();
    auto words = QRegularExpression("xMax=\"([0-9.]+)\"[^>]*>([^<]*)<").globalMatch(boxes);
    int count = 0;
    while (words.hasNext()) {
      const auto m = words.next();
      ++count;
      QVERIFY2(m.captured(1).toDouble() <= pageWidth - 20.0,
               qPrintable(m.captured(2) + " ends at " + m.captured(1) + " of " + QString::number(pageWidth)));
    }
    QVERIFY(count > 20);
    for (const std::string& cell : t.rows[0])
      if (cell.size() <= 12)
        QVERIFY2(text.contains(QString::fromStdString(cell)),
                 qPrintable(QString::fromStdString(cell) + " broken in\n" + text));
    QString compact = text;
    compact.remove(QRegularExpression("\\s"));
    QVERIFY(compact.contains(QString::fromStdString(r.logs[0].sha256)));
    // The page images, to look at.
    QProcess::execute("pdftoppm", {"-png", "-r", "60", pdf, QString(FLEXARM_SCREENSHOT_DIR) + "/layout_report"});
  }

  void cleanupTestCase() {
    delete window_;
    QSettings().clear();
  }
};

int main(int argc, char** argv) { return test::runWidgetTest<LayoutTest>(argc, argv, "FlexArmLayoutTests"); }

#include "tst_layout.moc"
