"""When and how often a call that broke off (UNAVAILABLE, a balancer's RST_STREAM) is made
again."""

from __future__ import annotations

import random
from dataclasses import dataclass
from typing import Iterator


@dataclass(frozen=True)


class RetryPolicy:
    """When and how often a call that broke off is made again (the C++ client's
    ``RetryPolicy``). The n-th retry waits ``min(initial_backoff * multiplier**(n-1),
    max_backoff)`` seconds, scaled by a random factor uniform in ``[1 - jitter, 1 + jitter]``;
    a wait that would end at or past the call's deadline is not taken (the call raises its last
    error). The defaults wait about 0.05, 0.1, 0.2, 0.4 s: a call gives up after ~0.75 s of
    failed attempts."""

    max_attempts: int = 5          # attempts in all, the first included; 1 turns retrying off
    initial_backoff: float = 0.05  # seconds before the first retry
    max_backoff: float = 2.0       # longest wait between two attempts (before jitter)
    multiplier: float = 2.0        # growth of the wait per retry
    jitter: float = 0.2            # relative spread of each wait, in [0, 1]

    def __post_init__(self) -> None:
        if self.max_attempts < 1:
            raise ValueError(f"max_attempts = {self.max_attempts}; must be at least 1")
        if not (self.initial_backoff >= 0 and self.max_backoff >= 0 and self.multiplier >= 1
                and 0 <= self.jitter <= 1):
            raise ValueError(f"{self}: backoffs must be >= 0, multiplier >= 1, jitter in "
                             "[0, 1]")

    def waits(self) -> Iterator[float]:
        """The waits before the 2nd, 3rd, ... attempt (``max_attempts - 1`` of them)."""
        backoff = self.initial_backoff
        for _ in range(self.max_attempts - 1):
            yield min(backoff, self.max_backoff) * random.uniform(1 - self.jitter,
                                                                  1 + self.jitter)
            backoff = min(backoff * self.multiplier, self.max_backoff)
