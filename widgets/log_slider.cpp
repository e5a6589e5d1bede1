#include "widgets/log_slider.h"

#include <QHBoxLayout>
#include <QLabel>
#include <QLineEdit>
#include <QSlider>
#include <algorithm>
#include <cmath>

namespace flexarm {

LogSlider::LogSlider(const QString& name, const QString& label, double lowest, double highest,
                     int stepsPerDecade, bool allowZero, QWidget* parent)
    : QWidget(parent), label_(new QLabel(label, this)), slider_(new QSlider(Qt::Horizontal, this)),
      field_(new QLineEdit(this)), lowExp_(std::log10(lowest)), highExp_(std::log10(highest)),
      steps_(stepsPerDecade), allowZero_(allowZero) {
  setObjectName(name);
  slider_->setObjectName(name + "Slider");
  field_->setObjectName(name + "Field");
  const int decades = static_cast<int>(std::lround(highExp_ - lowExp_));
  slider_->setRange(allowZero_ ? 0 : 1, decades * steps_ + 1);
  // An arrow key or a click on the track moves one position (a factor 10^(1/stepsPerDecade)),
  // never a whole decade; Page Up/Down do the same, dragging reaches any position.
  slider_->setSingleStep(1);
  slider_->setPageStep(1);
  slider_->setMinimumWidth(60);
  slider_->setToolTip(tr("%1 .. %2, %3 steps per decade%4")
                          .arg(lowest)
                          .arg(highest)
                          .arg(steps_)
                          .arg(allowZero_ ? tr("; far left is 0") : QString()));
  // The field holds any value it shows ("0.00025", "1e-08") without cutting it.
  field_->setMinimumWidth(field_->fontMetrics().horizontalAdvance("0.000025") + 16);
  field_->setMaximumWidth(field_->minimumWidth() + 10);
  field_->setToolTip(tr("Type a value; the slider moves to the nearest position"));
  label_->setMinimumWidth(label_->fontMetrics().horizontalAdvance(label) + 6);
  auto* layout = new QHBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(label_);
  layout->addWidget(slider_, 1);
  layout->addWidget(field_);
  connect(slider_, &QSlider::valueChanged, this, &LogSlider::onSlider);
  connect(field_, &QLineEdit::editingFinished, this, &LogSlider::onField);
  setValue(valueAt(slider_->minimum()));
}

int LogSlider::positionOf(double v) const {
  if (allowZero_ && v <= 0.0) return 0;
  const double e = std::clamp(std::log10(std::max(v, 1e-300)), lowExp_, highExp_);
  return 1 + static_cast<int>(std::lround((e - lowExp_) * steps_));
}

double LogSlider::valueAt(int position) const {
  if (position <= 0) return allowZero_ ? 0.0 : std::pow(10.0, lowExp_);
  // Whole decades land on exact powers of ten (1e-8, not 9.999e-9).
  const int k = position - 1;
  if (k % steps_ == 0) return std::pow(10.0, lowExp_ + k / steps_);
  return std::pow(10.0, lowExp_ + static_cast<double>(k) / steps_);
}

void LogSlider::setValue(double v) {
  if (!std::isfinite(v)) return;
  if (!(allowZero_ && v <= 0.0))
    v = std::clamp(v, std::pow(10.0, lowExp_), std::pow(10.0, highExp_));
  value_ = v;
  updating_ = true;
  slider_->setValue(positionOf(v));
  updating_ = false;
  showValue();
}

void LogSlider::showValue() { field_->setText(QString::number(value_, 'g', 4)); }

void LogSlider::onSlider(int position) {
  if (updating_) return;
  value_ = valueAt(position);
  showValue();
  emit valueChanged(value_);
}

void LogSlider::onField() {
  bool ok = false;
  const double v = field_->text().trimmed().toDouble(&ok);
  if (!ok || !std::isfinite(v) || v < 0.0 || (!allowZero_ && v == 0.0)) {
    field_->setToolTip(tr("'%1' is not %2").arg(field_->text(), allowZero_ ? tr("a number >= 0")
                                                                         : tr("a positive number")));
    field_->setStyleSheet("background: #fbd5d5");
    showValue();
    return;
  }
  field_->setStyleSheet(QString());
  field_->setToolTip(tr("Type a value; the slider moves to the nearest position"));
  const double old = value_;
  setValue(v);
  if (value_ != old) emit valueChanged(value_);
}

}  // namespace flexarm
