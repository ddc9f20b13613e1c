"""python -m atrous.eval: see atrous.eval.main."""
import sys

from . import main

sys.exit(main())
