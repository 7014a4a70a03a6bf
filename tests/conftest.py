"""What every test shares: the Ctrl-C tests send SIGINT to the programs they start, and
a program started with SIGINT ignored (as a shell starts a background job, and passes it
on) never sees it. Caught here, SIGINT goes back to its default in every child."""

import signal

if signal.getsignal(signal.SIGINT) == signal.SIG_IGN:
    signal.signal(signal.SIGINT, signal.default_int_handler)
