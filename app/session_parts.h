#pragma once
// The window's side of the session parts (core/session/session_part.h): how each part's
// section is captured from the window and restored into it. A capability that adds a core
// part adds its capture/restore pair to windowSessionParts() in app/session_parts.cpp.
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "core/session/session.h"

namespace flexarm {

class MainWindow;

struct WindowSessionPart {
  const char* key;  // the core part's key
  // The section as it stands in the window; null when there is nothing to save.
  nlohmann::json (*capture)(const MainWindow& window);
  // Applies a validated section. Called only after every fallible step of opening succeeded.
  void (*restore)(const nlohmann::json& section, MainWindow& window);
  // Returns the window's side to its state without the section, when an opened session has
  // none (so nothing of the previous session is shown or saved again); null: nothing to do.
  void (*reset)(MainWindow& window) = nullptr;
  // Logs the section names besides the window's own (e.g. a fault-free reference), added to
  // the session's log list when it is saved (name, path, read options; the checksum is formed
  // on saving); null: none.
  std::vector<LogReference> (*logs)(const MainWindow& window) = nullptr;
};

const std::vector<WindowSessionPart>& windowSessionParts();

}  // namespace flexarm
