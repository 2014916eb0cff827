"""Widgets: the main window and its editors. Everything here may import Qt."""
