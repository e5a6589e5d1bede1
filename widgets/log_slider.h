#pragma once
// A design weight on a logarithmic slider with a number field: the slider steps through
// decades (stepsPerDecade positions each) between lowest and highest, its leftmost position
// means exactly 0 (weights such as Q1 = diag(100, 1, 0, 0, 0) have zero entries), and the
// field takes any non-negative number, which moves the slider to the nearest position.
#include <QWidget>

class QLabel;
class QLineEdit;
class QSlider;

namespace flexarm {

class LogSlider : public QWidget {
  Q_OBJECT
 public:
  // objectName is set to name; the slider is name + "Slider", the field name + "Field".
  LogSlider(const QString& name, const QString& label, double lowest, double highest,
            int stepsPerDecade, bool allowZero, QWidget* parent = nullptr);

  double value() const { return value_; }
  // Sets the value (clamped to the range; 0 only when allowed) without emitting valueChanged.
  void setValue(double v);
  QSlider* slider() const { return slider_; }
  QLineEdit* field() const { return field_; }
  // Slider position of a value and value of a position (0 for position 0 with allowZero).
  int positionOf(double v) const;
  double valueAt(int position) const;

 signals:
  void valueChanged(double value);

 private:
  void onSlider(int position);
  void onField();
  void showValue();

  QLabel* label_;
  QSlider* slider_;
  QLineEdit* field_;
  double lowExp_, highExp_;
  int steps_;
  bool allowZero_;
  double value_ = 0.0;
  bool updating_ = false;
};

}  // namespace flexarm
