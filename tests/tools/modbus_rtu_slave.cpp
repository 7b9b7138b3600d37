// A Modbus-RTU slave made with libmodbus (Debian libmodbus-dev), for the Serial Gateway
// tests: fins_test_modbus_slave DEVICE SLAVE_ID. Serves 100 coils, discrete inputs,
// holding and input registers (holding register n starts as n, input register n as
// 1000 + n) until the line goes away. Prints "ready" once listening.
#include <modbus/modbus.h>

#include <cerrno>
#include <cstdio>
#include <cstdlib>

int main(int argc, char** argv) {
    if (argc != 3) {
        std::fprintf(stderr, "usage: fins_test_modbus_slave DEVICE SLAVE_ID\n");
        return 2;
    }
    modbus_t* ctx = modbus_new_rtu(argv[1], 9600, 'E', 8, 1);
    if (ctx == nullptr) return 3;
    modbus_set_slave(ctx, std::atoi(argv[2]));
    if (modbus_connect(ctx) != 0) {
        std::fprintf(stderr, "fins_test_modbus_slave: %s: %s\n", argv[1], modbus_strerror(errno));
        return 3;
    }
    modbus_mapping_t* map = modbus_mapping_new(100, 100, 100, 100);
    for (int i = 0; i < 100; ++i) {
        map->tab_registers[i] = static_cast<uint16_t>(i);
        map->tab_input_registers[i] = static_cast<uint16_t>(1000 + i);
    }
    std::printf("ready\n");
    std::fflush(stdout);
    uint8_t query[MODBUS_RTU_MAX_ADU_LENGTH];
    for (;;) {
        const int n = modbus_receive(ctx, query);
        if (n > 0) {
            modbus_reply(ctx, query, n, map);
        } else if (n == -1 && errno != EMBBADCRC && errno != EMBBADDATA && errno != ETIMEDOUT) {
            break;  // the line is gone
        }
    }
    modbus_mapping_free(map);
    modbus_close(ctx);
    modbus_free(ctx);
    return 0;
}
