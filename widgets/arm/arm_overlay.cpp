#include "widgets/arm/arm_overlay.h"

#include <QCoreApplication>
#include <QFontMetrics>
#include <QLinearGradient>
#include <QPainter>
#include <QRect>
#include <algorithm>

namespace flexarm {
namespace {

// Light text with a dark shadow, legible on every part of the scene's background.
void shadowedText(QPainter& p, const QRect& box, int flags, const QString& text) {
  p.setPen(QColor(0, 0, 0, 170));
  p.drawText(box.translated(1, 1), flags, text);
  p.setPen(QColor(245, 245, 245));
  p.drawText(box, flags, text);
}

}  // namespace

void paintArmOverlay(QPainter& p, const QRect& area, const ArmOverlay& o) {
  if (!o.visible) return;
  p.save();
  QFont font = p.font();
  font.setPointSizeF(8.5);
  p.setFont(font);
  const QRect inner = area.adjusted(8, 6, -8, -6);
  shadowedText(p, inner, Qt::AlignLeft | Qt::AlignTop | Qt::TextWordWrap, o.caption);
  shadowedText(p, inner, Qt::AlignLeft | Qt::AlignBottom, o.status);
  if (o.legend && o.colour && o.maxDeflection > 0) {
    const QFontMetrics fm(font);
    const int w = 14, h = std::max(60, area.height() * 2 / 5);
    const QRect bar(area.right() - 12 - w - fm.horizontalAdvance("-0.000"), area.center().y() - h / 2, w, h);
    QLinearGradient g(bar.bottomLeft(), bar.topLeft());
    for (int i = 0; i <= 8; ++i)
      g.setColorAt(i / 8.0, o.colour(o.maxDeflection * (i / 4.0 - 1.0)));
    p.fillRect(bar, g);
    p.setPen(QColor(20, 20, 20));
    p.drawRect(bar);
    const double mrad = 1e3 * o.maxDeflection;
    const QString top = QString::number(mrad, 'g', 3), bottom = QString::number(-mrad, 'g', 3);
    auto label = [&](int y, const QString& text) {
      shadowedText(p, QRect(bar.right() + 4, y - fm.height() / 2, 200, fm.height()),
                   Qt::AlignLeft | Qt::AlignVCenter, text);
    };
    label(bar.top(), top);
    label(bar.center().y(), "0");
    label(bar.bottom(), bottom);
    shadowedText(p, QRect(bar.left() - 60, bar.top() - 2 * fm.height() - 6, w + 120, 2 * fm.height()),
                 Qt::AlignHCenter | Qt::AlignBottom, QCoreApplication::translate("ArmOverlay", "deflection\n[mrad]"));
  }
  p.restore();
}

}  // namespace flexarm
