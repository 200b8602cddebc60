"""``python -m tubekit`` runs the console script (:func:`tubekit.app.cli.main`)."""

__all__: list[str] = []

if __name__ == "__main__":
    import sys

    from tubekit.app.cli import main

    sys.exit(main())
