"""The map reports: the stress, sensor and reliability maps, each a folder of reports/ written as one
set (:mod:`cell.reporting.maps.map_report`)."""
