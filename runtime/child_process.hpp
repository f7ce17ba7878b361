// Ending a child process that was asked to stop: wait for it, SIGKILL it when it takes too long.
#pragma once

#include <sys/types.h>

namespace fusecal {

// Waits for child `pid` to exit (reaping it); after `grace_s` sends SIGKILL and waits for that.
void ReapOrKill(pid_t pid, double grace_s);

}  // namespace fusecal
