#pragma once
// The progress dialog of a read whose length is not known (opening a log, listing what a file
// holds): made once per owner, shown only when the read takes longer than 400 ms, kept until
// the owner hides it; Cancel sets the owner's flag, which the owner reads when the read ends.
#include <QProgressDialog>
#include <QString>
#include <QWidget>

namespace flexarm {

inline void startBusyProgress(QProgressDialog*& dialog, QWidget* parent, const QString& title,
                              const QString& label, bool* cancelled) {
  if (!dialog) {
    dialog = new QProgressDialog(parent);
    dialog->setWindowTitle(title);
    dialog->setMinimumDuration(400);
    dialog->setAutoClose(false);
    dialog->setAutoReset(false);
    QObject::connect(dialog, &QProgressDialog::canceled, parent, [cancelled] { *cancelled = true; });
  }
  *cancelled = false;
  dialog->setLabelText(label);
  dialog->reset();
  dialog->setRange(0, 0);
}

}  // namespace flexarm
