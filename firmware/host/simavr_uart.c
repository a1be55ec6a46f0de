/* Run the UNO build of the firmware in simavr with its UART0 bridged to stdin/stdout.
 * Usage: simavr_uart firmware.elf SECONDS < script
 * The script has lines "<ms> <hex bytes>": the bytes reach the UART at that simulated time
 * (one byte per 100 us, just above the 115200 baud byte time). Everything the firmware sends
 * on the UART is copied to stdout. Build: cc simavr_uart.c -o simavr_uart -lsimavr -lelf
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <simavr/avr_uart.h>
#include <simavr/sim_avr.h>
#include <simavr/sim_elf.h>
#include <simavr/sim_time.h>

static void on_output(struct avr_irq_t* irq, uint32_t value, void* param) {
  (void)irq; (void)param;
  putchar((int)value);
  fflush(stdout);
}

int main(int argc, char** argv) {
  if (argc != 3) { fprintf(stderr, "usage: %s firmware.elf seconds < script\n", argv[0]); return 2; }
  elf_firmware_t firmware;
  memset(&firmware, 0, sizeof(firmware));
  if (elf_read_firmware(argv[1], &firmware) != 0) { fprintf(stderr, "cannot read %s\n", argv[1]); return 2; }
  avr_t* avr = avr_make_mcu_by_name("atmega328p");
  if (avr == NULL) return 2;
  avr_init(avr);
  avr->frequency = 16000000;
  avr_load_firmware(avr, &firmware);
  avr->log = 0;
  uint32_t flags = 0;  /* no stdio echo of the UART from simavr itself */
  avr_ioctl(avr, AVR_IOCTL_UART_GET_FLAGS('0'), &flags);
  flags &= ~AVR_UART_FLAG_STDIO;
  avr_ioctl(avr, AVR_IOCTL_UART_SET_FLAGS('0'), &flags);
  avr_irq_register_notify(avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_OUTPUT),
                          on_output, NULL);
  avr_irq_t* input = avr_io_getirq(avr, AVR_IOCTL_UART_GETIRQ('0'), UART_IRQ_INPUT);

  static unsigned char bytes[65536];
  static avr_cycle_count_t when[65536];
  size_t count = 0;
  char line[8192];
  while (fgets(line, sizeof(line), stdin) != NULL && count < sizeof(bytes)) {
    char* hex = NULL;
    double ms = strtod(line, &hex);
    avr_cycle_count_t at = avr_usec_to_cycles(avr, (uint32_t)(ms * 1000));
    for (; hex && hex[0] && hex[1] && count < sizeof(bytes); ) {
      if (hex[0] == ' ' || hex[0] == '\n') { ++hex; continue; }
      unsigned value;
      if (sscanf(hex, "%2x", &value) != 1) break;
      bytes[count] = (unsigned char)value;
      when[count++] = at;
      at += avr_usec_to_cycles(avr, 100);
      hex += 2;
    }
  }
  avr_cycle_count_t end = avr_usec_to_cycles(avr, (uint32_t)(atof(argv[2]) * 1e6));
  size_t next = 0;
  while (avr->cycle < end) {
    while (next < count && avr->cycle >= when[next]) avr_raise_irq(input, bytes[next++]);
    int state = avr_run(avr);
    if (state == cpu_Done || state == cpu_Crashed) break;
  }
  return 0;
}
