"""The package version, in a module of its own so that modules inside the package (the dataset
generator's metadata) can import it without importing the package ``__init__``."""

__version__ = "0.1.0"
