// The pdnav Android app. Kotlin sources in src/main/kotlin, plain framework APIs (no AndroidX),
// the C++ core built by the NDK from the project's root CMakeLists.txt (core-cpp/jni ->
// libpdnav_jni.so for each ABI). Host verification of the same source sets: tools/android-host/run.
plugins {
    alias(libs.plugins.android.application)
    alias(libs.plugins.kotlin.android)
}

android {
    namespace = "org.pdnav.app"
    compileSdk = libs.versions.compileSdk.get().toInt()
    ndkVersion = libs.versions.ndk.get()

    defaultConfig {
        applicationId = "org.pdnav.app"
        minSdk = libs.versions.minSdk.get().toInt()   // API 24: raw GNSS measurements
        targetSdk = libs.versions.targetSdk.get().toInt()
        versionCode = 1
        versionName = "0.1.0"
        ndk {
            abiFilters += listOf("arm64-v8a", "x86_64")
        }
        externalNativeBuild {
            cmake {
                // Only the core and the bridge: host tools, tests and benchmarks are off.
                // c++_static: libpdnav_jni.so is the only native library, so the STL is
                // linked into it (no libc++_shared.so to ship, no ODR clash possible).
                arguments += listOf(
                    "-DPDNAV_BUILD_TESTS=OFF",
                    "-DPDNAV_BUILD_BENCHMARKS=OFF",
                    "-DPDNAV_BUILD_JVM_TESTS=OFF",
                    "-DANDROID_STL=c++_static",
                )
                // Without network: FetchContent takes these local sources instead (gradle.properties).
                val eigen = providers.gradleProperty("pdnav.eigenDir").orNull.orEmpty()
                val fastFloat = providers.gradleProperty("pdnav.fastFloatDir").orNull.orEmpty()
                if (eigen.isNotEmpty()) arguments += "-DFETCHCONTENT_SOURCE_DIR_EIGEN=$eigen"
                if (fastFloat.isNotEmpty()) arguments += "-DFETCHCONTENT_SOURCE_DIR_FAST_FLOAT=$fastFloat"
                targets += listOf("pdnav_jni")
            }
        }
    }

    externalNativeBuild {
        cmake {
            path = file("../CMakeLists.txt")
            version = libs.versions.cmake.get()
        }
    }

    sourceSets {
        getByName("main") {
            java.srcDirs("src/main/kotlin")
            manifest.srcFile("src/main/AndroidManifest.xml")
            res.srcDirs("src/main/res")
        }
    }

    buildTypes {
        getByName("release") {
            isMinifyEnabled = false
        }
    }

    compileOptions {
        sourceCompatibility = JavaVersion.VERSION_17
        targetCompatibility = JavaVersion.VERSION_17
    }
}

// No jvmToolchain pin (it would need a toolchain resolver to download a JDK): the JDK that
// runs Gradle (17+) compiles, targeting Java 17 bytecode.
kotlin {
    compilerOptions {
        jvmTarget.set(org.jetbrains.kotlin.gradle.dsl.JvmTarget.JVM_17)
    }
}

// The unit tests (JUnit + Robolectric, tests/jvm) run on the host through
// tools/android-host/run, which needs the host-built libpdnav_jni.so; Gradle has none here.
dependencies {
    implementation(libs.osmdroid)
}
