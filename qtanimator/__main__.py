from qtanimator.cli import main

raise SystemExit(main())
