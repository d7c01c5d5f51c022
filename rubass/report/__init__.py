"""`rubass report`: one self-contained HTML page of evidence for a certifier (docs/report.md)."""
