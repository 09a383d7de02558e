// Root build: plugin versions come from gradle/libs.versions.toml (also read by the host
// verification, tools/android-host/run).
plugins {
    alias(libs.plugins.android.application) apply false
    alias(libs.plugins.kotlin.android) apply false
}
