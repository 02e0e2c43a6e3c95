"""The package version, one definition read by ``mdi_envs`` and the kernel cache's digest."""

__version__ = "0.1.0"
