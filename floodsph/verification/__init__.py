"""Exact solutions of the analytic cases and the cases that run them through the solver."""
