#pragma once
// SIGINT (Ctrl-C) and SIGTERM end a long-running command cleanly: the handler only records the
// request, the command's loop looks at it, finishes its step and writes its logs and summary.
namespace epichead::tools {

// Installs `handler` (async-signal-safe: it may only store to an atomic) for SIGINT and SIGTERM.
void on_stop_signals(void (*handler)(int));

}  // namespace epichead::tools
