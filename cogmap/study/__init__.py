"""Reproduction studies."""
