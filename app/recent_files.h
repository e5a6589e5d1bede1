#pragma once
// Most-recently-used file lists kept in QSettings (recent logs, recent sessions).
#include <QFileInfo>
#include <QSettings>
#include <QStringList>

namespace flexarm {

inline QStringList recentList(const QString& key) { return QSettings().value(key).toStringList(); }

// Puts path (made absolute) first in the list under key, keeping at most max entries.
inline void addToRecentList(const QString& key, const QString& path, int max) {
  QStringList list = recentList(key);
  const QString abs = QFileInfo(path).absoluteFilePath();
  list.removeAll(abs);
  list.prepend(abs);
  while (list.size() > max) list.removeLast();
  QSettings().setValue(key, list);
}

}  // namespace flexarm
