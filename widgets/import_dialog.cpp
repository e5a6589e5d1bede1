#include "widgets/import_dialog.h"

#include <QComboBox>
#include <QDialogButtonBox>
#include <QDoubleSpinBox>
#include <QFileInfo>
#include <QGridLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QHeaderView>
#include <QLabel>
#include <QLineEdit>
#include <QPushButton>
#include <QScreen>
#include <QSpinBox>
#include <QTreeWidget>
#include <QVBoxLayout>
#include <QtConcurrent>
#include <qcustomplot.h>

#include "widgets/plots/plot_tools.h"

namespace flexarm {
namespace {

enum ItemData { kExpression = Qt::UserRole, kRows, kCols, kNumeric };

const char* const kRoleNames[] = {"time", "input", "output", "arm", "reference"};

// "(not said)" first, then the units; data: the unit's text.
void fillUnits(QComboBox* box, std::initializer_list<SignalUnit> units) {
  box->addItem(QObject::tr("not said"), QString());
  for (SignalUnit u : units) box->addItem(toString(u), QString(toString(u)));
}

void selectData(QComboBox* box, const QString& value) {
  const int i = box->findData(value);
  box->setCurrentIndex(i < 0 ? 0 : i);
}

QTreeWidgetItem* itemFor(const SourceEntry& e) {
  auto* item = new QTreeWidgetItem({QString::fromStdString(e.label), QString::fromStdString(e.shape),
                                    QString::fromStdString(e.unreadable.empty() ? e.kind : e.kind + " (skipped)")});
  item->setData(0, kExpression, QString::fromStdString(e.expression));
  item->setData(0, kRows, static_cast<qulonglong>(e.rows));
  item->setData(0, kCols, static_cast<qulonglong>(e.cols));
  item->setData(0, kNumeric, e.numeric);
  if (!e.unreadable.empty()) {
    item->setDisabled(true);
    item->setToolTip(0, QObject::tr("Skipped: %1").arg(QString::fromStdString(e.unreadable)));
  } else {
    item->setToolTip(0, QString::fromStdString(e.expression));
  }
  for (const auto& c : e.children) item->addChild(itemFor(c));
  return item;
}

}  // namespace

ImportDialog::ImportDialog(const QString& path, SourceListing listing, const LogReadOptions& start, QWidget* parent)
    : QDialog(parent), path_(path), listing_(std::move(listing)) {
  setObjectName("importDialog");
  setWindowTitle(tr("Import %1").arg(QFileInfo(path).fileName()));
  auto* grid = new QGridLayout(this);

  // Left: what the file holds, and the selection.
  auto* left = new QVBoxLayout;
  const bool mat = listing_.format == LogFormat::Mat;
  auto* intro = new QLabel(mat ? tr("Variables of %1. Pick one (a row or column of a matrix), see it, and give it a role.")
                                     .arg(QFileInfo(path).fileName())
                               : tr("Columns of %1. Pick one, see it, and give it a role.").arg(QFileInfo(path).fileName()));
  intro->setWordWrap(true);
  left->addWidget(intro);
  tree_ = new QTreeWidget;
  tree_->setObjectName("importTree");
  tree_->setHeaderLabels({tr("Name"), tr("Size"), tr("Class")});
  tree_->header()->setSectionResizeMode(0, QHeaderView::Stretch);
  tree_->setMinimumWidth(380);
  left->addWidget(tree_, 1);
  auto* selection = new QHBoxLayout;
  slice_ = new QComboBox;
  slice_->setObjectName("importSlice");
  slice_->addItem(tr("row"), "row");
  slice_->addItem(tr("column"), "column");
  sliceIndex_ = new QSpinBox;
  sliceIndex_->setObjectName("importSliceIndex");
  sliceIndex_->setRange(1, 1);
  selected_ = new QLineEdit;
  selected_->setObjectName("importSelection");
  selected_->setPlaceholderText(mat ? tr("MATLAB expression, e.g. rec.tau(1,:)") : tr("column"));
  selection->addWidget(slice_);
  selection->addWidget(sliceIndex_);
  selection->addWidget(selected_, 1);
  left->addLayout(selection);
  if (!listing_.notes.empty()) {
    QString notes;
    for (const auto& n : listing_.notes) notes += (notes.isEmpty() ? "" : "\n") + QString::fromStdString(n);
    auto* skipped = new QLabel(notes);
    skipped->setObjectName("importNotes");
    skipped->setWordWrap(true);
    left->addWidget(skipped);
  }
  grid->addLayout(left, 0, 0, 2, 1);

  // Right: the preview, then the roles, units, sides.
  previewLabel_ = new QLabel(tr("Pick a variable to see it"));
  previewLabel_->setObjectName("importPreviewLabel");
  previewLabel_->setWordWrap(true);
  plot_ = new QCustomPlot;
  plot_->setObjectName("importPreview");
  plot_->setMinimumHeight(180);
  plot_->addGraph();
  plot_->xAxis->setLabel(tr("sample"));
  plot_->setInteractions(QCP::iRangeDrag | QCP::iRangeZoom);
  PlotTools::install(plot_);
  auto* previewBox = new QVBoxLayout;
  previewBox->addWidget(previewLabel_);
  previewBox->addWidget(plot_, 1);
  grid->addLayout(previewBox, 0, 1);

  auto* form = new QGridLayout;
  const QString roleText[] = {tr("Time (s)"), tr("Input (torque)"), tr("Output (motor encoder)"),
                              tr("Arm angle (arm encoder)"), tr("Reference (as the output)")};
  const std::string* given[] = {&start.mapping.time, &start.mapping.input, &start.mapping.output, &start.mapping.arm,
                                &start.mapping.reference};
  for (int r = 0; r < 5; ++r) {
    roles_[r] = new QLineEdit(QString::fromStdString(*given[r]));
    roles_[r]->setObjectName(QString("importRole_") + kRoleNames[r]);
    roles_[r]->setPlaceholderText(r == 0 ? tr("none: give the sample time") : r >= 3 ? tr("none") : tr("the file's default"));
    auto* use = new QPushButton(tr("Use selection"));
    use->setObjectName(QString("importUse_") + kRoleNames[r]);
    connect(use, &QPushButton::clicked, this, [this, r] { useSelectionAs(static_cast<Role>(r)); });
    form->addWidget(new QLabel(roleText[r]), r, 0);
    form->addWidget(roles_[r], r, 1);
    form->addWidget(use, r, 2);
  }
  outputUnit_ = new QComboBox;
  outputUnit_->setObjectName("importOutputUnit");
  fillUnits(outputUnit_, {SignalUnit::Rad, SignalUnit::Deg, SignalUnit::Rev, SignalUnit::RadPerS, SignalUnit::DegPerS,
                          SignalUnit::Rpm, SignalUnit::M, SignalUnit::Mm, SignalUnit::MPerS, SignalUnit::MmPerS});
  selectData(outputUnit_, start.mapping.outputUnit ? toString(*start.mapping.outputUnit) : "");
  outputSide_ = new QComboBox;
  outputSide_->setObjectName("importOutputSide");
  outputSide_->addItem(tr("not said"), QString());
  outputSide_->addItem(tr("motor shaft"), "motor");
  outputSide_->addItem(tr("arm side (scaled by the gear)"), "arm");
  selectData(outputSide_, start.mapping.outputSide ? toString(*start.mapping.outputSide) : "");
  armUnit_ = new QComboBox;
  armUnit_->setObjectName("importArmUnit");
  fillUnits(armUnit_, {SignalUnit::Rad, SignalUnit::Deg, SignalUnit::Rev});
  selectData(armUnit_, start.mapping.armUnit ? toString(*start.mapping.armUnit) : "");
  gearRatio_ = new QLineEdit(QString::fromStdString(start.mapping.gearRatio));
  gearRatio_->setObjectName("importGearRatio");
  gearRatio_->setPlaceholderText(tr("arm/motor, e.g. 1/256.86"));
  // A ratio above 1 is a gear ratio typed as datasheets give it (motor turns per arm turn):
  // its inverse is offered beside the field as soon as it is typed, before anything is read.
  invertGear_ = new QPushButton;
  invertGear_->setObjectName("importGearInvert");
  invertGear_->hide();
  connect(invertGear_, &QPushButton::clicked, this, [this] {
    gearRatio_->setText(QString::fromStdString(invertedGearRatio(gearRatio_->text().toStdString())));
  });
  connect(gearRatio_, &QLineEdit::textChanged, this, &ImportDialog::checkGearRatio);
  auto* gearBox = new QWidget;
  auto* gearRow = new QHBoxLayout(gearBox);
  gearRow->setContentsMargins(0, 0, 0, 0);
  gearRow->addWidget(gearRatio_, 1);
  gearRow->addWidget(invertGear_);
  inputScale_ = new QDoubleSpinBox;
  inputScale_->setObjectName("importInputScale");
  inputScale_->setDecimals(6);
  inputScale_->setRange(-1e9, 1e9);
  inputScale_->setValue(start.mapping.inputScale);
  inputScale_->setToolTip(tr("The input times this is the torque in N m (the force in N), e.g. 35.15 N/V"));
  sampleTime_ = new QDoubleSpinBox;
  sampleTime_->setObjectName("importSampleTime");
  sampleTime_->setDecimals(6);
  sampleTime_->setRange(0.0, 1e6);
  sampleTime_->setSpecialValueText(tr("from the time"));
  sampleTime_->setSuffix(" s");
  sampleTime_->setValue(start.sampleTime);
  // Units and sides below the roles, two to a row, so the expressions keep their width.
  auto* units = new QGridLayout;
  const std::pair<QString, QWidget*> unitRows[] = {
      {tr("Output unit"), outputUnit_}, {tr("Output given on"), outputSide_},
      {tr("Arm angle unit"), armUnit_}, {tr("Gear ratio"), gearBox},
      {tr("Input scale"), inputScale_}, {tr("Sample time (no time)"), sampleTime_}};
  for (int i = 0; i < 6; ++i) {
    units->addWidget(new QLabel(unitRows[i].first), i / 2, 2 * (i % 2));
    units->addWidget(unitRows[i].second, i / 2, 2 * (i % 2) + 1);
  }
  units->setColumnStretch(1, 1);
  units->setColumnStretch(3, 1);
  auto* choices = new QGroupBox(tr("What is what"));
  auto* choicesLayout = new QVBoxLayout(choices);
  form->setColumnStretch(1, 1);
  choicesLayout->addLayout(form);
  choicesLayout->addLayout(units);
  grid->addWidget(choices, 1, 1);

  problem_ = new QLabel;
  problem_->setObjectName("importProblem");
  problem_->setWordWrap(true);
  problem_->setStyleSheet("color: #b00020");
  problem_->hide();
  grid->addWidget(problem_, 2, 0, 1, 2);
  auto* buttons = new QDialogButtonBox(QDialogButtonBox::Open | QDialogButtonBox::Cancel);
  buttons->setObjectName("importButtons");
  connect(buttons, &QDialogButtonBox::accepted, this, &ImportDialog::accept);
  connect(buttons, &QDialogButtonBox::rejected, this, &QDialog::reject);
  grid->addWidget(buttons, 3, 0, 1, 2);
  grid->setColumnStretch(0, 2);
  grid->setColumnStretch(1, 3);
  grid->setRowStretch(0, 1);

  fillTree();
  connect(tree_, &QTreeWidget::currentItemChanged, this, &ImportDialog::onItemChanged);
  connect(slice_, &QComboBox::currentIndexChanged, this, &ImportDialog::updateSelection);
  connect(sliceIndex_, &QSpinBox::valueChanged, this, &ImportDialog::updateSelection);
  connect(selected_, &QLineEdit::editingFinished, this, [this] { showPreview(selected_->text().trimmed()); });
  connect(&previewer_, &QFutureWatcher<Preview>::finished, this, &ImportDialog::onPreviewRead);
  onItemChanged();
  checkGearRatio();
  // Fits a 1366x768 screen.
  const QRect screen = parent && parent->screen() ? parent->screen()->availableGeometry() : QRect(0, 0, 1366, 768);
  resize(std::min(1120, screen.width() - 40), std::min(680, screen.height() - 60));
}

ImportDialog::~ImportDialog() { previewer_.waitForFinished(); }

void ImportDialog::fillTree() {
  for (const auto& e : listing_.entries) tree_->addTopLevelItem(itemFor(e));
  tree_->resizeColumnToContents(1);
  tree_->resizeColumnToContents(2);
  // A struct that holds signals (arrays of more than a hundred numbers) is shown open.
  for (int i = 0; i < tree_->topLevelItemCount(); ++i) {
    QTreeWidgetItem* top = tree_->topLevelItem(i);
    bool holdsSignals = false;
    for (int c = 0; c < top->childCount() && c < 200 && !holdsSignals; ++c)
      holdsSignals = top->child(c)->data(0, kNumeric).toBool() &&
                 top->child(c)->data(0, kRows).toULongLong() * top->child(c)->data(0, kCols).toULongLong() > 100;
    top->setExpanded(holdsSignals);
  }
}

void ImportDialog::onItemChanged() {
  QTreeWidgetItem* item = tree_->currentItem();
  const bool numeric = item && item->data(0, kNumeric).toBool();
  const qulonglong rows = item ? item->data(0, kRows).toULongLong() : 0;
  const qulonglong cols = item ? item->data(0, kCols).toULongLong() : 0;
  const bool matrix = numeric && rows > 1 && cols > 1;
  slice_->setEnabled(matrix);
  sliceIndex_->setEnabled(matrix);
  if (matrix) {
    // A matrix of a few long rows (one per axis) is read by rows, else by columns.
    const QSignalBlocker b1(slice_), b2(sliceIndex_);
    slice_->setCurrentIndex(rows < cols ? 0 : 1);
    sliceIndex_->setRange(1, static_cast<int>(std::min<qulonglong>(rows < cols ? rows : cols, 1u << 30)));
    sliceIndex_->setValue(1);
  }
  updateSelection();
}

void ImportDialog::updateSelection() {
  QTreeWidgetItem* item = tree_->currentItem();
  if (!item || !item->data(0, kNumeric).toBool()) {
    selected_->setText(item ? item->data(0, kExpression).toString() : QString());
    return;
  }
  QString e = item->data(0, kExpression).toString();
  if (slice_->isEnabled()) {
    const bool row = slice_->currentData().toString() == "row";
    const qulonglong size = item->data(0, row ? kRows : kCols).toULongLong();
    sliceIndex_->setMaximum(static_cast<int>(std::min<qulonglong>(size, 1u << 30)));
    e += row ? QString("(%1,:)").arg(sliceIndex_->value()) : QString("(:,%1)").arg(sliceIndex_->value());
  }
  selected_->setText(e);
  showPreview(e);
}

bool ImportDialog::select(const QString& expression, int index) {
  QTreeWidgetItemIterator it(tree_);
  for (; *it; ++it)
    if ((*it)->data(0, kExpression).toString() == expression) {
      tree_->setCurrentItem(*it);
      if (index > 0 && sliceIndex_->isEnabled()) sliceIndex_->setValue(index);
      return true;
    }
  return false;
}

QString ImportDialog::selectedExpression() const { return selected_->text().trimmed(); }

void ImportDialog::useSelectionAs(Role role) {
  roles_[static_cast<int>(role)]->setText(selectedExpression());
  problem_->hide();
}

void ImportDialog::showPreview(const QString& expression) {
  if (expression.isEmpty()) return;
  if (previewer_.isRunning()) {  // the newest choice is read when this one ends
    pending_ = expression;
    return;
  }
  previewing_ = expression;
  previewLabel_->setText(tr("Reading %1...").arg(expression));
  const std::string path = path_.toStdString(), e = expression.toStdString();
  const QString time = roles_[0]->text().trimmed();
  const std::string t = time == expression ? std::string() : time.toStdString();
  const auto read = [path, e, t](const SourceListing& listing) {
    Preview p;
    p.values = readSourceSeries(path, listing, e);
    if (p.values.ok && !t.empty()) p.time = readSourceSeries(path, listing, t);
    return p;
  };
  if (listing_.format != LogFormat::Mat) {  // the columns are in memory already
    QFutureInterface<Preview> done;
    done.reportStarted();
    done.reportResult(read(listing_));
    done.reportFinished();
    previewer_.setFuture(done.future());
    return;
  }
  previewer_.setFuture(QtConcurrent::run([read, format = listing_.format] {
    SourceListing l;
    l.format = format;
    return read(l);
  }));
}

void ImportDialog::onPreviewRead() {
  const Preview preview = previewer_.result();
  const SeriesRead& r = preview.values;
  const QString expression = previewing_;
  QCPGraph* g = plot_->graph(0);
  points_ = 0;
  if (r.ok) {
    // Against the chosen time when it has as many samples, else the sample time, else samples.
    const bool timed = preview.time.ok && preview.time.values.size() == r.values.size();
    const double ts = sampleTime_->value();
    const auto xAt = [&](std::size_t i) {
      return timed ? preview.time.values[i] : ts > 0.0 ? static_cast<double>(i) * ts : static_cast<double>(i + 1);
    };
    plot_->xAxis->setLabel(timed || ts > 0.0 ? tr("time (s)") : tr("sample"));
    // At most a few thousand points are drawn: min and max of each bucket keep the envelope.
    const std::size_t n = r.values.size(), buckets = 2000;
    QVector<double> x, y;
    if (n <= 2 * buckets) {
      for (std::size_t i = 0; i < n; ++i) {
        x.append(xAt(i));
        y.append(r.values[i]);
      }
    } else {
      for (std::size_t b = 0; b < buckets; ++b) {
        const std::size_t from = b * n / buckets, to = (b + 1) * n / buckets;
        const auto [lo, hi] = std::minmax_element(r.values.begin() + static_cast<std::ptrdiff_t>(from),
                                                  r.values.begin() + static_cast<std::ptrdiff_t>(to));
        const auto first = std::min(lo, hi), second = std::max(lo, hi);  // in time order
        x.append(xAt(static_cast<std::size_t>(first - r.values.begin())));
        y.append(*first);
        x.append(xAt(static_cast<std::size_t>(second - r.values.begin())));
        y.append(*second);
      }
    }
    g->setData(x, y);
    points_ = static_cast<int>(x.size());
    plot_->rescaleAxes();
    const auto [lo, hi] = std::minmax_element(r.values.begin(), r.values.end());
    previewLabel_->setText(tr("%1: %2 samples, %3 to %4")
                               .arg(expression)
                               .arg(n)
                               .arg(*lo, 0, 'g', 6)
                               .arg(*hi, 0, 'g', 6));
  } else {
    g->data()->clear();
    previewLabel_->setText(QString::fromStdString(r.error.problem));
  }
  plot_->replot();
  emit previewShown(expression, points_);
  if (!pending_.isEmpty()) {
    const QString next = pending_;
    pending_.clear();
    if (next != expression) showPreview(next);
  }
}

QString ImportDialog::previewTitle() const { return previewLabel_->text(); }
QString ImportDialog::previewAxis() const { return plot_->xAxis->label(); }
int ImportDialog::previewPoints() const { return points_; }

LogReadOptions ImportDialog::options() const {
  LogReadOptions o;
  o.format = listing_.format;
  LogMapping& m = o.mapping;
  std::string* roles[] = {&m.time, &m.input, &m.output, &m.arm, &m.reference};
  for (int r = 0; r < 5; ++r) *roles[r] = roles_[r]->text().trimmed().toStdString();
  m.outputUnit = signalUnitFromString(outputUnit_->currentData().toString().toStdString());
  m.armUnit = signalUnitFromString(armUnit_->currentData().toString().toStdString());
  m.outputSide = encoderSideFromString(outputSide_->currentData().toString().toStdString());
  m.gearRatio = gearRatio_->text().trimmed().toStdString();
  m.inputScale = inputScale_->value();
  o.sampleTime = sampleTime_->value();
  return o;
}

void ImportDialog::checkGearRatio() {
  const std::string text = gearRatio_->text().trimmed().toStdString();
  const std::optional<double> r = text.empty() ? std::nullopt : parseGearRatio(text, nullptr);
  const bool above = r && *r > 1.0;
  if (above) {
    const QString inverse = QString::fromStdString(invertedGearRatio(text));
    invertGear_->setText(tr("Use %1").arg(inverse));
    invertGear_->setToolTip(tr("The gear ratio is arm/motor: a reduction of %1 motor turns per arm turn is %2")
                                .arg(QString::fromStdString(text), inverse));
    std::string why;
    LogMapping m;
    m.gearRatio = text;
    m.isValid(&why);
    why[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(why[0])));
    setProblem(QString::fromStdString(why) + ".");
  } else if (!invertGear_->isHidden()) {
    setProblem({});
  }
  invertGear_->setVisible(above);
}

bool ImportDialog::gearRatioInversionOffered() const { return !invertGear_->isHidden(); }

void ImportDialog::setProblem(const QString& text) {
  problem_->setText(text);
  problem_->setVisible(!text.isEmpty());
}

void ImportDialog::accept() {
  const LogReadOptions o = options();
  std::string why;
  if (listing_.format != LogFormat::FlexArmCsv && (o.mapping.input.empty() || o.mapping.output.empty()))
    why = "Choose the input and the output (pick a variable, then Use selection).";
  else if (!o.isValid(&why))
    why[0] = static_cast<char>(std::toupper(static_cast<unsigned char>(why[0])));
  if (!why.empty()) {
    setProblem(QString::fromStdString(why));
    return;
  }
  QDialog::accept();
}

}  // namespace flexarm
