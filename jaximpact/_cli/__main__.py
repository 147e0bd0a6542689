"""`python -m jaximpact._cli`: the command line."""

from . import main

raise SystemExit(main())
