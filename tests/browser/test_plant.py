"""A plant in the browser: the list of CPU Units by network opens each one's own view."""
from selenium.webdriver.common.by import By

from conftest import cell_text, go_to, open_page, screenshot, wait_for

PLANT = """
[[plc]]
name = "press1"
profile = "cj2h"
[[plc.ethernet]]
unit = 0
network = 1
bind = "127.0.0.1"
node = 1
address_method = "table"

[[plc]]
name = "oven"
profile = "cs1h"
[[plc.ethernet]]
unit = 0
network = 1
bind = "127.0.0.1"
node = 2
address_method = "table"
"""


def test_plant_list_opens_a_cpu_unit(finsd_factory, page):
    finsd = finsd_factory(config=PLANT)
    oven = finsd.unit_port("oven")
    finsd.fins("--dest", "1.2", "write", "D100", 4321, port=oven)
    finsd.fins("write", "D100", 1111)
    open_page(page, finsd.url)
    units = wait_for(lambda: page.find_elements(By.CSS_SELECTOR, "#plant-list .unit"), 5, "the CPU Units")
    assert [u.get_attribute("data-plc") for u in units] == ["press1", "oven"]
    assert "Network 1" in page.find_element(By.ID, "plant-list").text
    # The first CPU Unit is open; its D100 is its own.
    go_to(page, "D100")
    wait_for(lambda: cell_text(page, 100) == "1111", 5, "press1's D100")
    page.find_element(By.CSS_SELECTOR, "#plant-list .unit[data-plc='oven']").click()
    wait_for(lambda: page.find_element(By.ID, "unit-title").text == "oven", 5, "oven's view")
    wait_for(lambda: page.find_element(By.ID, "cpu-model").text.startswith("CS1H"), 5, "oven's model")
    wait_for(lambda: cell_text(page, 100) == "4321", 5, "oven's D100")
    assert "plc=oven" in page.current_url
    screenshot(page, "plant-oven")
    # The view is linkable: the address bar opens the same CPU Unit.
    open_page(page, page.current_url)
    wait_for(lambda: page.find_element(By.ID, "unit-title").text == "oven", 5, "oven from the URL")
