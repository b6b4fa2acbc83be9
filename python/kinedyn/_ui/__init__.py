"""What kinedyn shows people: terminal tables that keep numbers whole (``terminal``), progress bars
for long work (``progress``), values made fit for JSON (``json``) and files written atomically and
read only when regular (``files``). The ground floor of the layers
in docs/architecture.md: it imports nothing else of kinedyn."""
