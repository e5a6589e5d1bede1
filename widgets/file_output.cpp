#include "widgets/file_output.h"

#include <QBuffer>
#include <QFileInfo>
#include <string>

#include "core/io/log_io.h"

namespace flexarm {

bool writeFileBytes(const QString& path, const QByteArray& bytes, QString* why) {
  std::string problem;
  const bool ok = writeFileAtomically(path.toStdString(), std::string(bytes.constData(), static_cast<std::size_t>(bytes.size())),
                                      &problem);
  if (!ok && why) *why = QString::fromStdString(problem);
  return ok;
}

bool saveImageFile(const QImage& image, const QString& path, const char* format, QString* why) {
  const QByteArray suffix = QFileInfo(path).suffix().toUpper().toLatin1();
  QByteArray bytes;
  QBuffer buffer(&bytes);
  buffer.open(QIODevice::WriteOnly);
  if (image.isNull() || !image.save(&buffer, format ? format : suffix.constData())) {
    if (why) *why = QString("cannot encode the image for %1").arg(path);
    return false;
  }
  return writeFileBytes(path, bytes, why);
}

}  // namespace flexarm
