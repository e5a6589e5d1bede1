#pragma once
// Files the window writes (reports, plot exports, snapshots, frames) go to the disk the one
// way every FlexArm file does (writeFileAtomically, core/io/log_io.h): drawn or encoded in
// memory, then a temporary sibling made exclusively under an unpredictable name, flushed and
// renamed; never written through a link.
#include <QByteArray>
#include <QImage>
#include <QString>

namespace flexarm {

// Writes bytes to path; false with a sentence in why (when given).
bool writeFileBytes(const QString& path, const QByteArray& bytes, QString* why = nullptr);

// Encodes image in format ("PNG"; null: from path's suffix) and writes it as writeFileBytes.
bool saveImageFile(const QImage& image, const QString& path, const char* format = nullptr,
                   QString* why = nullptr);

}  // namespace flexarm
